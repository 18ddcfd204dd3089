"""The built-in navigation server of ROS 2 runs: Nav2's `navigate_to_pose`,
`navigate_through_poses`, `follow_waypoints` and `compute_path_to_pose` actions, served over the
rcl_action wire (nav2_wire.py) the way a Nav2 stack serves them, so rclpy's ActionClient and
nav2_simple_commander's BasicNavigator work against it.

One goal at a time, as bt_navigator runs one: a new NavigateToPose goal preempts the one
running, which ends ABORTED (Nav2's SimpleActionServer aborts the current goal when it accepts a
pending one); a goal of the other navigator meanwhile is refused (bt_navigator's
NavigatorMuxer). A goal is planned at once (nav2_navigation.plan_path: a goal that cannot be
reached ends ABORTED with a sentence), then driven each control period until the goal checker
says it is reached (SUCCEEDED), the progress checker says the robot is stuck (ABORTED), or a
client cancels it (CANCELED). Recoveries (spin, back up, wait) are not run: number_of_recoveries
stays 0 and a failure ends the goal. `navigate_through_poses` plans leg by leg into one path;
its number_of_poses_remaining counts the poses not yet passed within 0.5 m (RemovePassedGoals).

`follow_waypoints` is Nav2's waypoint follower (nav2_waypoints.py).

Parameters (the run's params): `controller_frequency` [Hz] (Nav2's default 20), `controller_service`
(a service a student node serves, robodojo_msgs/srv/ComputeVelocityCommands: the thesis's
Stanley controller, 003_4f92d1fa0a49ddae.txt section 5.9; unset: the built-in follower),
`xy_goal_tolerance` [m], `yaw_goal_tolerance` [rad] (Nav2's 0.25 and 0.25), `stop_on_failure`,
`planner` ("astar", NavFn-like, or "hybrid_astar", SMAC Hybrid-A*-like, as the thesis plans for
its Stanley controller) and `minimum_turning_radius` [m] (SMAC's 0.4).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from sandbox.action_goals import Goal, GoalEvent, GoalStatus, GoalTransitionError
from sandbox.msgs import get_message_class
from sandbox.runtime import format_log_line
from sandbox.services import request_topic
from sandbox.units import NS_PER_S
from server.runs.builtin import BuiltinNode, Planner
from server.runs.nav2_follow import GoalChecker, PurePursuit
from server.runs.nav2_navigation import PLANNERS, Navigation, NoPath, Pose, plan_path, yaw_of
from server.runs.nav2_waypoints import WaypointFollower
from server.runs.nav2_wire import (
    SERVICE_CALL,
    ActionWire,
    ServiceClient,
    duration_msg,
    reply,
    stamp_ns,
    time_msg,
    with_error,
)
from server.sim.geometry import yaw_quaternion

if TYPE_CHECKING:
    from server.runs.core import RunCore as Run  # built-ins are handed the run's core

CONTROLLER_FREQUENCY_HZ = 20.0  # [Hz] Nav2's controller_server default
SERVICE_PATIENCE_S = 1.0  # [s] a goal waits this long for an unserved controller service
TURNING_RADIUS_M = 0.4  # [m] SMAC Hybrid-A*'s minimum_turning_radius default
CONTROLLER_SERVICE_TYPE = "robodojo_msgs/srv/ComputeVelocityCommands"
NAVIGATE = "navigate_to_pose"
THROUGH = "navigate_through_poses"
PASSED_RADIUS_M = 0.5  # [m] a via pose counts as passed this close (RemovePassedGoals' radius)
FOLLOW = "follow_waypoints"
COMPUTE_PATH = "compute_path_to_pose"
GLOBAL_FRAMES = ("map", "")  # goal frames used as they are (Nav2 transforms others via tf)


def _msg(name: str, **fields: Any) -> Any:
    return get_message_class(name)(**fields)


def _pose_stamped(x: float, y: float, yaw: float, time_ns: int) -> Any:
    return _msg(
        "geometry_msgs/msg/PoseStamped",
        header=_msg("std_msgs/msg/Header", stamp=time_msg(time_ns), frame_id="map"),
        pose=_msg(
            "geometry_msgs/msg/Pose",
            position=_msg("geometry_msgs/msg/Point", x=float(x), y=float(y)),
            orientation=_msg("geometry_msgs/msg/Quaternion", **yaw_quaternion(yaw)._asdict()),
        ),
    )


def _twist(v: float, w: float) -> Any:
    twist = _msg("geometry_msgs/msg/Twist")
    twist.linear.x, twist.angular.z = float(v), float(w)
    return twist


class NavigationServer(BuiltinNode):
    name = "nav2"
    publishes = (("plan", "nav_msgs/msg/Path"),)
    rate_hz = CONTROLLER_FREQUENCY_HZ
    ros2_native = True

    def graph_subscriptions(self) -> tuple[tuple[str, str], ...]:
        """The actions' request topics: clients' wait_for_server looks for their subscriber."""
        return tuple(
            (request_topic(f"{action}/_action/{service}"), SERVICE_CALL)
            for action in (NAVIGATE, THROUGH, FOLLOW, COMPUTE_PATH)
            for service in ("send_goal", "get_result", "cancel_goal")
        )

    # ------------------------------------------------------------------ start
    def start(self, run: Run) -> list[tuple[str, object]]:
        from sandbox.msgs2 import get_action_class, get_service_class

        if run.builtins.get("localization") is None:
            raise ValueError(
                "the nav2 built-in navigates on the localization built-in's pose; "
                "add 'localization' to the run's built-in nodes"
            )
        params = run.spec.params
        self.rate_hz = float(params.get("controller_frequency", CONTROLLER_FREQUENCY_HZ))
        if not self.rate_hz > 0:
            raise ValueError(f"controller_frequency must be above 0 Hz, not {self.rate_hz}")
        self.planner = Planner()
        self.planner.start(run)
        self.xy_tol = float(params.get("xy_goal_tolerance", GoalChecker.xy_tolerance_m))
        self.yaw_tol = float(params.get("yaw_goal_tolerance", GoalChecker.yaw_tolerance_rad))
        self.stop_on_failure = bool(params.get("stop_on_failure", True))
        self.planner_kind = str(params.get("planner", "astar"))
        if self.planner_kind not in PLANNERS:
            raise ValueError(
                f"planner '{self.planner_kind}' is unknown; use one of {', '.join(PLANNERS)}"
            )
        self.turning_radius_m = float(params.get("minimum_turning_radius", TURNING_RADIUS_M))
        self.navigate = ActionWire(NAVIGATE, get_action_class("nav2_msgs/action/NavigateToPose"))
        self.through = ActionWire(
            THROUGH, get_action_class("nav2_msgs/action/NavigateThroughPoses")
        )
        self.follow = ActionWire(FOLLOW, get_action_class("nav2_msgs/action/FollowWaypoints"))
        self.compute = ActionWire(
            COMPUTE_PATH, get_action_class("nav2_msgs/action/ComputePathToPose")
        )
        service = params.get("controller_service")
        self.client = (
            ServiceClient(
                str(service).strip("/"), get_service_class(CONTROLLER_SERVICE_TYPE), self.name
            )
            if service
            else None
        )
        self.follower = PurePursuit()
        self.pose: Pose | None = None
        self.current: Navigation | None = None
        self.waypoints = WaypointFollower(self)
        self.subscribes = ("pose",) + ((self.client.reply_topic,) if self.client else ())
        for wire in (self.navigate, self.through, self.follow, self.compute):
            for topic, type_name in wire.published:
                run.bus.declare_topic(topic, type_name, self.name)
            run.bus.topics[wire.status_topic].latched_by.add(self.name)  # transient local
        return []

    def log(self, run: Run, level: str, text: str) -> None:
        run.outputs.log(self.name, [format_log_line(level, run.time_s, text)])

    # ------------------------------------------------------------------ requests
    def on_message(self, run: Run, topic: str, message: object) -> list[tuple[str, object]]:
        if topic == "pose":
            p = message.pose
            self.pose = (p.position.x, p.position.y, yaw_of(p.orientation))
            return []
        if self.client is not None and topic == self.client.reply_topic:
            return self._controller_answer(run, message)
        for wire in (self.navigate, self.through, self.follow, self.compute):
            if topic in wire.request_topics:
                request = wire.request(topic, message)
                if topic == wire.send_goal:
                    return self._send_goal(run, wire, message, request)
                if topic == wire.get_result:
                    return self._get_result(wire, message, request)
                return self._cancel(run, wire, message, request)
        return []

    def _send_goal(self, run: Run, wire: ActionWire, call: Any, request: Any) -> list:
        uuid = bytes(request.goal_id.uuid)
        busy = self.current is not None and self.current.wire is not wire
        if wire in (self.navigate, self.through) and busy:
            # bt_navigator's NavigatorMuxer: one navigator at a time, the other's goals refused
            self.log(run, "WARN", f"{wire.name}: refused while {self.current.wire.name} runs")
            return [reply(call, wire.goal_response(False, run.time_ns))]
        try:
            goal = wire.goals.accept(uuid, run.time_ns, request.goal)
        except GoalTransitionError:
            return [reply(call, wire.goal_response(False, run.time_ns))]
        out = [reply(call, wire.goal_response(True, run.time_ns))]
        goal.update(GoalEvent.EXECUTE)
        out.append(wire.status())
        if wire in (self.navigate, self.through):
            out += self._start_navigation(run, goal, wire)
        elif wire is self.follow:
            out += self.waypoints.start(run, goal)
        else:
            out += self._compute_path(run, goal)
        return out

    def _compute_path(self, run: Run, goal: Goal) -> list:
        """The planner server's ComputePathToPose: a path at once (not published on `plan`,
        which shows the path being followed)."""
        request, result = goal.request, self.compute.action.Result()
        start = request.start.pose if request.use_start else None
        begin = (start.position.x, start.position.y, yaw_of(start.orientation)) if start else None
        end = request.goal.pose
        try:
            if (begin or self.pose) is None:
                raise NoPath("no pose from the localization yet", "TF_ERROR")
            target = (end.position.x, end.position.y, yaw_of(end.orientation))
            points, yaws = self._plan(begin or self.pose, target)
        except NoPath as error:
            code = "PLANNER_TF_ERROR" if error.code == "TF_ERROR" else error.code
            with_error(result, code, str(error))
            return self._end(run, self.compute, goal, GoalEvent.ABORT, result, str(error))
        result.path = self._path_message(points, yaws, run.time_ns)
        return self._end(run, self.compute, goal, GoalEvent.SUCCEED, result)

    def _plan(self, start: Pose, goal: Pose) -> tuple[Any, Any]:
        return plan_path(self.planner, start, goal, self.planner_kind, self.turning_radius_m)

    def _path_message(self, points: Any, yaws: Any, time_ns: int) -> Any:
        path = _msg("nav_msgs/msg/Path")
        path.header = _msg("std_msgs/msg/Header", stamp=time_msg(time_ns), frame_id="map")
        path.poses = [
            _pose_stamped(x, y, yaw, time_ns) for (x, y), yaw in zip(points, yaws, strict=True)
        ]
        return path

    def _get_result(self, wire: ActionWire, call: Any, request: Any) -> list:
        now, goal = wire.goals.result_request(bytes(request.goal_id.uuid), call)
        if not now:
            return []
        if goal is None:
            return [reply(call, wire.result_response(GoalStatus.UNKNOWN, None))]
        return [reply(call, wire.result_response(goal.status, goal.result))]

    def _cancel(self, run: Run, wire: ActionWire, call: Any, request: Any) -> list:
        info = request.goal_info
        code, canceling = wire.goals.cancel(bytes(info.goal_id.uuid), stamp_ns(info.stamp))
        out = [reply(call, wire.cancel_response(code, canceling))]
        if canceling:
            out.append(wire.status())
        for goal in canceling:
            if wire is self.follow:
                out += self.waypoints.cancel(run, goal)
            elif wire in (self.navigate, self.through):
                out += self._cancel_navigation(run, goal.uuid, wire)
        return out

    def _cancel_navigation(
        self, run: Run, uuid: bytes | None, wire: ActionWire | None = None
    ) -> list:
        wire = wire or self.navigate
        goal = wire.goals.goals.get(uuid) if uuid else None
        if goal is None or goal.status.terminal:
            return []
        if goal.status is not GoalStatus.CANCELING:
            goal.update(GoalEvent.CANCEL_GOAL)
        if self.current is not None and self.current.uuid == uuid:
            return self._finish_navigation(run, GoalEvent.CANCELED, "", "canceled by a client")
        return self._end(run, wire, goal, GoalEvent.CANCELED, wire.action.Result())

    # ------------------------------------------------------------------ navigation
    def _start_navigation(self, run: Run, goal: Goal, wire: ActionWire | None = None) -> list:
        wire = wire or self.navigate
        out = []
        if self.current is not None:
            out += self._finish_navigation(
                run, GoalEvent.ABORT, "PREEMPTED", "preempted: a newer goal arrived"
            )
        self.current = None
        request = goal.request
        targets = [request.pose] if wire is self.navigate else list(request.poses)
        frames = {target.header.frame_id.strip("/") for target in targets}
        if request.behavior_tree:
            return out + self._abort_now(
                run, goal, "FAILED_TO_LOAD_BEHAVIOR_TREE",
                "the lab's navigator runs Nav2's default behaviour tree only; "
                "leave behavior_tree empty", wire,
            )  # fmt: skip
        if not targets:
            return out + self._abort_now(run, goal, "UNKNOWN", "no poses to go through", wire)
        if not frames <= set(GLOBAL_FRAMES):
            return out + self._abort_now(
                run, goal, "TF_ERROR",
                f"a goal is in frame '{sorted(frames - set(GLOBAL_FRAMES))[0]}'; the lab's "
                "navigator takes goals in 'map'", wire,
            )  # fmt: skip
        if self.pose is None:
            return out + self._abort_now(
                run, goal, "TF_ERROR", "no pose from the localization yet", wire
            )
        ends = [(t.pose.position.x, t.pose.position.y, yaw_of(t.pose.orientation)) for t in targets]
        legs, start = [], self.pose
        try:
            for end in ends:  # through poses: one plan per leg, joined
                points, yaws = self._plan(start, end)
                legs.append((points, yaws) if not legs else (points[1:], yaws[1:]))
                start = end
        except NoPath as error:
            self.log(run, "WARN", f"{wire.name}: {error}")
            return out + self._abort_now(run, goal, error.code, str(error), wire)
        points = np.concatenate([leg[0] for leg in legs])
        yaws = np.concatenate([leg[1] for leg in legs])
        end = ends[-1]
        self.current = Navigation(
            goal.uuid, end, points, run.time_ns, GoalChecker(self.xy_tol, self.yaw_tol), wire=wire
        )
        self.current.via = [e[:2] for e in ends[:-1]]
        self.follower.reset()
        path = self._path_message(points, yaws, run.time_ns)
        self.path_message = path
        self.log(run, "INFO", f"{wire.name}: heading to ({end[0]:.2f}, {end[1]:.2f})")
        return [*out, ("plan", path)]

    def _abort_now(
        self, run: Run, goal: Goal, code: str, message: str, wire: ActionWire | None = None
    ) -> list:
        wire = wire or self.navigate
        result = with_error(wire.action.Result(), code, message)
        out = self._end(run, wire, goal, GoalEvent.ABORT, result, message)
        return out + self.waypoints.navigation_ended(run, goal, GoalStatus.ABORTED, result)

    def _finish_navigation(self, run: Run, event: GoalEvent, code: str, message: str) -> list:
        nav, self.current = self.current, None
        if nav is None:
            return []
        wire = nav.wire
        goal = wire.goals.goals[nav.uuid]
        result = with_error(wire.action.Result(), code, message if code else "")
        out = [(run.velocity_topic, _twist(0.0, 0.0))]
        if message and event is not GoalEvent.SUCCEED:
            self.log(run, "WARN" if event is GoalEvent.ABORT else "INFO",
                     f"{wire.name}: {message}")  # fmt: skip
        out += self._end(run, wire, goal, event, result, message)
        return out + self.waypoints.navigation_ended(run, goal, goal.status, result)

    def _end(self, run: Run, wire: ActionWire, goal: Goal, event: GoalEvent, result: Any,
             message: str = "") -> list:  # fmt: skip
        waiting = wire.goals.finish(goal, event, result, message)
        out = [wire.status()]
        response = wire.result_response(goal.status, result)
        out += [reply(call, response) for call in waiting]
        return out

    # ------------------------------------------------------------------ control
    def tick(self, run: Run) -> list[tuple[str, object]]:
        out = self.waypoints.resume(run)
        nav = self.current
        if nav is None or self.pose is None:
            return out
        pose = self.pose
        if nav.reached(pose):
            return out + self._finish_navigation(run, GoalEvent.SUCCEED, "", "")
        if not nav.progress.check(pose[0], pose[1], run.time_s):
            return out + self._finish_navigation(
                run, GoalEvent.ABORT, "FAILED_TO_MAKE_PROGRESS",
                f"the robot moved less than {nav.progress.radius_m} m in "
                f"{nav.progress.time_allowance_s:.0f} s; it is stuck",
            )  # fmt: skip
        if self.client is None:
            v, w = self.follower.command(
                pose, nav.points, nav.goal[2], nav.goal_checker.xy_reached, 1.0 / self.rate_hz
            )
            out.append((run.velocity_topic, _twist(v, w)))
        else:
            out += self._call_controller(run, nav, pose)
        speed = run.sim.state.linear_m_s
        feedback = nav.wire.action.Feedback(
            current_pose=_pose_stamped(*pose, run.time_ns),
            navigation_time=duration_msg((run.time_ns - nav.started_ns) / NS_PER_S),
            estimated_time_remaining=duration_msg(nav.eta_s(pose, speed)),
            number_of_recoveries=0,
            distance_remaining=nav.distance_remaining(pose),
        )
        if nav.wire is self.through:  # via poses drop out as the robot passes them
            while nav.via and math.dist(nav.via[0], pose[:2]) <= PASSED_RADIUS_M:
                nav.via.pop(0)
            feedback.number_of_poses_remaining = len(nav.via) + 1
        out.append(nav.wire.feedback(nav.uuid, feedback))
        return out

    def _call_controller(self, run: Run, nav: Navigation, pose: Pose) -> list:
        client = self.client
        if not run.bus.has_subscribers(client.topic):
            if nav.service_missing_since_ns is None:
                nav.service_missing_since_ns = run.time_ns
                self.log(run, "WARN", f"controller service '{client.service}' is not available")
            if run.time_ns - nav.service_missing_since_ns >= SERVICE_PATIENCE_S * NS_PER_S:
                return self._finish_navigation(
                    run, GoalEvent.ABORT, "INVALID_CONTROLLER",
                    f"no node serves '{client.service}' ({CONTROLLER_SERVICE_TYPE}): the "
                    "controller calls it every control period; create it with "
                    "node.create_service()",
                )  # fmt: skip
            return [(run.velocity_topic, _twist(0.0, 0.0))]
        nav.service_missing_since_ns = None
        if nav.pending_call is not None:
            nav.missed_periods += 1
            if nav.missed_periods == 1:  # once per goal, not every period
                self.log(
                    run, "WARN",
                    f"controller service '{client.service}' took longer than one control "
                    f"period ({1.0 / self.rate_hz:.3f} s) to answer",
                )  # fmt: skip
            return []
        request = client.service_class.Request(
            pose=_pose_stamped(*pose, run.time_ns), path=self.path_message
        )
        nav.pending_call, message = client.call(request)
        nav.pending_since_ns = run.time_ns
        return [message]

    def _controller_answer(self, run: Run, message: Any) -> list:
        nav = self.current
        if nav is None or message.id != nav.pending_call:
            return []  # the answer to a goal that has ended
        nav.pending_call = None
        try:
            response = self.client.response(message)
        except ValueError as error:
            return self._finish_navigation(
                run, GoalEvent.ABORT, "NO_VALID_CONTROL",
                f"controller service '{self.client.service}' failed: {error}",
            )  # fmt: skip
        twist = response.cmd_vel
        return [(run.velocity_topic, _twist(twist.linear.x, twist.angular.z))]
