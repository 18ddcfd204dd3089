"""Nav2's waypoint follower for the nav2 built-in (nav2_server.py): a FollowWaypoints goal
becomes one NavigateToPose goal per waypoint, as nav2_waypoint_follower sends them as a client
of navigate_to_pose (so they show on its status topic), with WaitAtWaypoint's 200 ms pause at
each and - `stop_on_failure`, true by default - the goal ABORTED with the missed waypoint when
one fails. `goal_index` and `number_of_loops` (Jazzy's goal fields) are honoured.

Sources (facts): nav2_waypoint_follower (waypoint_follower.cpp: the loop, missed waypoints and
their error codes), nav2_msgs/action/FollowWaypoints and msg/MissedWaypoint.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from sandbox.action_goals import Goal, GoalEvent, GoalStatus
from sandbox.msgs import get_message_class
from sandbox.units import NS_PER_S
from server.runs.nav2_wire import with_error

if TYPE_CHECKING:
    from server.runs.core import RunCore as Run  # built-ins are handed the run's core
    from server.runs.nav2_server import NavigationServer

WAYPOINT_PAUSE_S = 0.2  # [s] WaitAtWaypoint's waypoint_pause_duration default (200 ms)


class Mission:
    """One FollowWaypoints goal: which waypoint, which failed, when the pause ends."""

    def __init__(self, goal: Goal, poses: list[Any], first: int, loops: int) -> None:
        self.goal, self.poses, self.index, self.loops = goal, poses, first, loops
        self.loop = 0
        self.missed: list[tuple[int, int]] = []  # (waypoint index, error code)
        self.nav_uuid: bytes | None = None
        self.resume_ns = 0


class WaypointFollower:
    """The follower's state; the server it drives its NavigateToPose goals through."""

    def __init__(self, server: NavigationServer) -> None:
        self.server = server
        self.mission: Mission | None = None

    def start(self, run: Run, goal: Goal) -> list:
        """A new FollowWaypoints goal (preempting one running: that one ends ABORTED)."""
        server, out = self.server, []
        if self.mission is not None:
            old, self.mission = self.mission, None
            out += server._end(run, server.follow, old.goal, GoalEvent.ABORT, self._result(old))
            out += server._cancel_navigation(run, old.nav_uuid)
        request = goal.request
        poses = list(request.poses)
        first = int(getattr(request, "goal_index", 0))
        loops = int(getattr(request, "number_of_loops", 0))
        if not poses or first >= len(poses):
            result = with_error(
                server.follow.action.Result(), "NO_VALID_WAYPOINTS", "no waypoints to follow"
            )
            return out + server._end(run, server.follow, goal, GoalEvent.ABORT, result)
        self.mission = Mission(goal, poses, first, loops)
        return out + self._next_goal(run)

    def cancel(self, run: Run, goal: Goal) -> list:
        """The client canceled the FollowWaypoints goal: its navigation too, then CANCELED."""
        mission = self.mission
        if mission is None or mission.goal is not goal:
            return []
        self.mission = None
        server = self.server
        out = server._cancel_navigation(run, mission.nav_uuid)
        result = self._result(mission)
        return out + server._end(run, server.follow, goal, GoalEvent.CANCELED, result)

    def _next_goal(self, run: Run) -> list:
        server, mission = self.server, self.mission
        uuid = _uuid(mission, run)
        request = server.navigate.action.Goal(pose=mission.poses[mission.index])
        goal = server.navigate.goals.accept(uuid, run.time_ns, request)
        goal.update(GoalEvent.EXECUTE)
        mission.nav_uuid = uuid
        feedback = server.follow.action.Feedback(current_waypoint=mission.index)
        return [
            server.navigate.status(),
            server.follow.feedback(mission.goal.uuid, feedback),
            *server._start_navigation(run, goal),
        ]

    def navigation_ended(self, run: Run, goal: Goal, status: GoalStatus, result: Any) -> list:
        """A NavigateToPose goal ended: if it was the mission's, note it and go on after the
        pause (or, on a failure with stop_on_failure, end the mission ABORTED)."""
        mission = self.mission
        if mission is None or goal.uuid != mission.nav_uuid:
            return []
        mission.nav_uuid = None
        if status is GoalStatus.SUCCEEDED:
            mission.resume_ns = run.time_ns + round(WAYPOINT_PAUSE_S * NS_PER_S)
            return []
        mission.missed.append((mission.index, int(getattr(result, "error_code", 0))))
        if self.server.stop_on_failure or status is GoalStatus.CANCELED:
            self.mission = None
            follow = self.server.follow
            return self.server._end(
                run, follow, mission.goal, GoalEvent.ABORT, self._result(mission)
            )
        mission.resume_ns = run.time_ns
        return []

    def resume(self, run: Run) -> list:
        """Each control period: after a waypoint's pause, the next one (or the end)."""
        mission = self.mission
        if mission is None or mission.nav_uuid is not None or run.time_ns < mission.resume_ns:
            return []
        mission.index += 1
        if mission.index >= len(mission.poses):
            if mission.loop >= mission.loops:
                self.mission = None
                result = self._result(mission)
                follow = self.server.follow
                return self.server._end(run, follow, mission.goal, GoalEvent.SUCCEED, result)
            mission.index, mission.loop = 0, mission.loop + 1
        return self._next_goal(run)

    def _result(self, mission: Mission) -> Any:
        result = self.server.follow.action.Result()
        fields = result.get_fields_and_field_types()
        if fields.get("missed_waypoints", "").startswith("sequence<int32"):
            result.missed_waypoints = [index for index, _ in mission.missed]  # Humble
        else:
            missed = get_message_class("nav2_msgs/msg/MissedWaypoint")
            result.missed_waypoints = [
                missed(index=index, goal=mission.poses[index], error_code=code)
                for index, code in mission.missed
            ]
        return result


def _uuid(mission: Mission, run: Run) -> bytes:
    """A goal id for the follower's own NavigateToPose goals: unique in the run and the same
    from run to run (lockstep runs repeat byte for byte)."""
    counter = run.time_ns.to_bytes(8, "big") + mission.index.to_bytes(4, "big")
    return b"wp" + mission.goal.uuid[:2] + counter
