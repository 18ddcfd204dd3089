"""A run: a robot backend, one or more sandboxed nodes, a clock, a topic bus and a recording.

    run = Run(spec, launcher, out_dir, observer=hub)   # observer: optional, see RunObserver
    result = run.execute()          # blocking: call it from a worker thread or the CLI
    run.command(Pause()) / run.command(Button(True)) / run.stop()   # any thread, meanwhile

The loop itself lives in server/runs/clocks.py (lockstep and realtime); this module owns the
lifecycle, the nodes, routing between them and the robot, controls, and the result. Nothing
that goes wrong in one run escapes `execute()`: a node that raises or is killed, a recorder
that fails, a simulator that raises - each ends this run with a reason and leaves others alone.
"""

from __future__ import annotations

import logging
import math
import threading
import time
import uuid
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path

import sandbox.services  # noqa: F401  # registers the service envelope types the recorder sees
from sandbox.launcher import Launcher
from sandbox.msgs import Time
from sandbox.msgs.geometry_msgs import Point, Pose, PoseStamped, Quaternion
from sandbox.msgs.std_msgs import Header
from sandbox.msgs.tf2_msgs import TFMessage
from sandbox.node_process import NodeProcess
from sandbox.protocol import (
    Artifact,
    Clock,
    Envelope,
    Exited,
    Finishing,
    NodeInfo,
    Outcome,
    RobotTopic,
    Yield,
)
from server.runs.builtin_host import BuiltinHost
from server.runs.bus import ROBOT, RUN, TopicBus
from server.runs.controls import RunControls
from server.runs.dialect import Dialect
from server.runs.faults import Faults
from server.runs.metrics import NodeMetrics
from server.runs.outputs import RunObserver, RunOutputs
from server.runs.recorder import Recorder
from server.runs.result import RunEnd, RunResult
from server.runs.spec import NodeSpec, RunSpec, RunSpecError
from server.runs.state import RunState, check_transition
from server.runs.tf import tf_message
from server.sim import Pose2D, Simulation
from server.sim.robots.base import CommandError, Direction
from server.sim.simulation import EventKind, SimulationError

log = logging.getLogger("robodojo.runs")

NS = 1_000_000_000
GOAL_TOPIC = "goal"  # RViz's "2D Nav Goal" idea: the run publishes the goal pose here
TF_TOPIC = "tf"  # the transform tree, recorded and published to nodes (tf2_ros listens here)
TF_PERIOD_NS = NS // 30  # [ns] /tf recorded at 30 Hz: smooth in Foxglove, small on disk
MAP_MARGIN_M = 0.5  # [m] beyond the world's bounds by this much, the robot left the map
LOG_LINES_KEPT = 2000  # per node in memory (the recording keeps them all)


@dataclass
class NodeSlot:
    """The run's view of one node."""

    spec: NodeSpec
    process: NodeProcess | None = None
    wake_at_ns: int | None = 0  # None: spinning (wake on messages)
    # Topics whose messages wake the node before wake_at_ns (services, wait_for_message);
    # None: only wake_at_ns, or any message while spinning.
    wake_on: frozenset[str] | None = None
    graph_version: int = -1  # the bus graph version this node was last sent
    done: bool = False
    finishing: bool = False  # ended its part; its Exited (files, figures) is still to come
    exited: Exited | None = None
    last_wake_ns: int | None = None
    newest_sensor_s: float | None = None  # publication time of the newest robot message seen
    woken_at_wall: float = 0.0
    metrics: NodeMetrics = field(default_factory=NodeMetrics)
    logs: deque = field(default_factory=lambda: deque(maxlen=LOG_LINES_KEPT))

    @property
    def name(self) -> str:
        return self.spec.name


class Run(RunControls, RunOutputs):
    def __init__(
        self,
        spec: RunSpec,
        launcher: Launcher,
        out_dir: str | Path,
        run_id: str | None = None,
        observer: RunObserver | None = None,
        backend: Simulation | None = None,
    ) -> None:
        spec.validate()
        if backend is not None and spec.clock is not Clock.REALTIME:
            raise RunSpecError("a run on a real robot needs the realtime clock")
        self.backend = backend  # a real robot (server/hardware/backend.py), else simulated
        self.observer = observer
        self.spec = spec
        self.dialect = Dialect(spec.ros_version)  # the robot's edge in the run's ROS dialect
        self.launcher = launcher
        self.run_id = run_id or uuid.uuid4().hex[:12]
        self.out_dir = Path(out_dir)
        self.state = RunState.CREATED
        self.reason = ""
        self.time_ns = 0
        self.duration_ns = round(spec.duration_s * NS)
        RunControls.__init__(self)
        self._state_lock = threading.Lock()
        self.faults = Faults()
        self.slots = {node.name: NodeSlot(node) for node in spec.nodes}
        self.bus = TopicBus()
        self.sim: Simulation | None = None
        self.recorder: Recorder | None = None
        self._next_tf_ns = 0
        self.clock_wall_s = 0.0  # wall time the clock ran (node start-up excluded)
        self._script = sorted(spec.script, key=lambda event: event[0])
        self.builtins = BuiltinHost(spec.builtin_nodes, self.dialect.ros_version)

    # ----------------------------------------------------------------------------- lifecycle
    def _move(self, new: RunState) -> None:
        with self._state_lock:
            check_transition(self.state, new)
            self.state = new
        self._tell_state(new)

    def execute(self) -> RunResult:
        """Run to the end and return the result. Never raises for anything a node does."""
        from server.runs.clocks import run_lockstep, run_realtime

        wall_start = time.monotonic()
        end_state, reason = RunState.FAILED, "failed: the run did not start"
        self._move(RunState.STARTING)
        try:
            self._prepare()
            self._start_nodes()
            self._move(RunState.RUNNING)
            loop = run_lockstep if self.spec.clock is Clock.LOCKSTEP else run_realtime
            self._clock_started = time.monotonic()
            try:
                loop(self)
            finally:
                self.clock_wall_s = time.monotonic() - self._clock_started
            end_state, reason = RunState.FINISHED, "finished: duration reached"
        except RunEnd as end:
            end_state, reason = end.state, end.reason
        except Exception as error:  # a fault of ours must end this run, not the server
            log.exception("run %s failed inside the engine", self.run_id)
            end_state, reason = RunState.FAILED, f"failed: internal error ({error!r})"
        if self.state is not RunState.STOPPING:
            self._move(RunState.STOPPING)
        return self._finish(end_state, reason, time.monotonic() - wall_start)

    def _prepare(self) -> None:
        spec = self.spec
        spawn = Pose2D(*spec.initial_pose) if spec.initial_pose else spec.spawn
        self.sim = self.backend or Simulation(spec.robot, spec.world, seed=spec.seed, spawn=spawn)
        self.out_dir.mkdir(parents=True, exist_ok=True)
        dialect = self.dialect
        self.recorder = Recorder(
            self.out_dir,
            self.run_id,
            profile="ros2" if dialect.ros2 else "ros1",
            metadata={
                "ros_version": str(dialect.ros_version),
                "robot": spec.robot,
                "world": spec.world,
                "clock": str(spec.clock),
                "seed": str(spec.seed),
                "duration_s": str(spec.duration_s),
                "nodes": ",".join(node.name for node in spec.nodes),
            },
        )
        for topic in self.sim.topics:
            type_name = dialect.type_name(topic.type_name)
            if dialect.command_types(topic.type_name, topic.direction):  # Twist, TwistStamped
                self.bus.allow_types(topic.name, type_name)  # recorded in the type sent
                continue
            self.bus.declare_topic(topic.name, type_name, ROBOT if topic.rate_hz else None)
            self.recorder.add_topic(topic.name, type_name)
        for name, ros1_type in ((GOAL_TOPIC, PoseStamped._type), (TF_TOPIC, TFMessage._type)):
            self.bus.declare_topic(name, dialect.type_name(ros1_type), RUN)
            self.recorder.add_topic(name, dialect.type_name(ros1_type))
        if spec.light_position is not None:
            movable = [light.name for light in self.sim.lights if light.movable]
            if movable:
                self.sim.move_light(movable[0], *spec.light_position)
        for published in self.sim.reset():
            self._from_robot(published.topic, published.message, 0.0)
        if spec.goal is not None:
            self._publish_goal(*spec.goal)

    def _node_info(self, node: NodeSpec) -> NodeInfo:
        topics = [
            RobotTopic(
                t.name,
                self.dialect.type_name(t.type_name),
                str(t.direction),
                t.rate_hz,
                accepts=self.dialect.command_types(t.type_name, t.direction),
            )
            for t in self.sim.topics
        ]
        goal_type = self.dialect.type_name(PoseStamped._type)
        topics.append(RobotTopic(GOAL_TOPIC, goal_type, "publish", None))
        topics.extend(
            RobotTopic(topic, kind, "publish", rate)
            for topic, kind, rate in self.builtins.published_topics(self)
        )
        velocity = self.velocity_topic
        return NodeInfo(
            node_name=node.name,
            robot=self.spec.robot,
            robot_topics=topics,
            velocity_topic=velocity,
            clock=self.spec.clock,
            start_time_s=0.0,
            params={**self.spec.params, **node.params},
            argv=list(node.args),
            remaps=dict(node.remaps),
            namespace=node.namespace,
            ros_version=self.dialect.ros_version,
        )

    def _start_nodes(self) -> None:
        for slot in self.slots.values():
            self.bus.add_node(slot.name)
            slot.process = self.launcher.start(slot.name)
        replies = []
        files = [Artifact(path, data) for path, data in self.spec.files]
        for slot in self.slots.values():
            node = slot.spec
            reply = slot.process.load(
                node.code, node.filename, node.api, self._node_info(node), files
            )
            replies.append((slot, reply))
        # Every node's subscriptions are known before anything published at start-up is
        # routed, so launch-file order does not lose a first message (as a latched topic).
        for slot, reply in replies:
            if isinstance(reply, Yield):
                self.bus.declare(slot.name, reply.advertised, reply.subscribed)
        for slot, reply in replies:
            self.handle_reply(slot, reply, timed=False)
        self.builtins.start(self)

    def _finish(self, end_state: RunState, reason: str, wall_s: float) -> RunResult:
        self._command_zero()
        for slot in self.slots.values():
            finishing = slot.finishing
            self._end_node(slot, reason)
            late = slot.exited
            if finishing and late is not None and end_state is RunState.FINISHED:
                # What a node did after its control part (figures, files) can still fail it.
                if late.outcome is Outcome.ERROR and late.error is not None:
                    self._log_lines(slot, late.error.traceback.rstrip("\n").split("\n"))
                    where = f" at line {late.error.line}" if late.error.line else ""
                    end_state = RunState.FAILED
                    reason = f"failed: node {slot.name} raised {late.error.type}{where}"
                elif late.outcome in (Outcome.KILLED, Outcome.CRASHED):
                    end_state, reason = RunState.FAILED, f"failed: {late.reason}"
        if self.recorder is not None:
            metrics = self.metrics()
            self.recorder.write_json("metrics", metrics)
            self.recorder.write_json("graph", self.bus.graph())
            paths = self.recorder.close()
            # Checked after close: the last batch (or the summary) may be what failed.
            if self.recorder.error and end_state is RunState.FINISHED:
                end_state, reason = RunState.FAILED, f"failed: {self.recorder.error}"
        else:
            metrics, paths = self.metrics(), {}
        self.reason = reason
        self._close_controls()
        self._move(end_state)
        return RunResult(
            run_id=self.run_id,
            state=end_state,
            reason=reason,
            duration_s=self.time_ns / NS,
            wall_s=wall_s,
            metrics=metrics["run"],
            nodes=metrics["nodes"],
            paths=paths,
            graph=self.bus.graph(),
            ros_version=self.dialect.ros_version,
        )

    def _end_node(self, slot: NodeSlot, reason: str) -> None:
        process = slot.process
        if process is None:
            return
        try:
            exited = slot.exited or process.shutdown(reason)
            slot.exited = exited
            self._collect_logs(slot)
            if self.recorder is not None and exited.artifacts:
                self.recorder.write_artifacts(
                    slot.name, [(a.name, a.data) for a in exited.artifacts]
                )
            for note in exited.notes:
                slot.logs.append(f"[artifacts] {note}")
        finally:
            process.close()
            slot.process = None

    def metrics(self) -> dict:
        state = self.sim.state if self.sim is not None else None
        run = {
            "collisions": state.contact_count if state else 0,
            "distance_travelled_m": state.distance_travelled_m if state else 0.0,
            "time_out_of_bounds_s": state.time_out_of_bounds_s if state else 0.0,
            "clock_wall_s": self.clock_wall_s,
            "ros_version": self.dialect.ros_version,
        }
        nodes = {}
        for slot in self.slots.values():
            summary = slot.metrics.summary()
            summary["outcome"] = str(slot.exited.outcome) if slot.exited else None
            summary["dropped_messages"] = (
                self.bus.dropped(slot.name) if slot.name in self.bus.nodes else 0
            )
            nodes[slot.name] = summary
        return {"run": run, "nodes": nodes}

    # ----------------------------------------------------------------------------- routing
    def handle_reply(
        self, slot: NodeSlot, reply: Yield | Finishing | Exited, timed: bool = True
    ) -> None:
        """Act on what a node said when it went back to sleep (or ended). `timed`: the reply
        answers a wake, so its wall time is a step's compute time (not start-up)."""
        if timed and not slot.finishing:
            slot.metrics.compute.add(time.perf_counter() - slot.woken_at_wall)
        self._collect_logs(slot)
        if isinstance(reply, Yield):
            self.bus.declare(slot.name, reply.advertised, reply.subscribed)
            if reply.unsubscribed:
                self.bus.unsubscribe(slot.name, reply.unsubscribed)
            self._from_node(slot, reply.published)
            slot.wake_at_ns = None if reply.wake_at_s is None else round(reply.wake_at_s * NS)
            slot.wake_on = None if reply.wake_on is None else frozenset(reply.wake_on)
            return
        self._from_node(slot, reply.published)
        self.bus.remove_node(slot.name)
        if isinstance(reply, Finishing):
            # The node's part in the run is over (its hooks' last messages are routed above);
            # its figures and files come with its Exited, within the end budget.
            slot.done, slot.finishing = True, True
            self._log_lines(slot, [f"[run] node finishing: {reply.reason}"])
            if all(s.done for s in self.slots.values()):
                raise RunEnd(RunState.FINISHED, "finished: every node ended")
            return
        slot.exited, slot.done, slot.finishing = reply, True, False
        if reply.error is not None:  # the student's traceback belongs in the node's log
            lines = reply.error.traceback.rstrip("\n").split("\n")
            self._log_lines(slot, lines)
        if reply.outcome is Outcome.FINISHED:
            if all(s.done for s in self.slots.values()):
                raise RunEnd(RunState.FINISHED, "finished: every node ended")
            return
        if reply.outcome is Outcome.ERROR and reply.error is not None:
            where = f" at line {reply.error.line}" if reply.error.line else ""
            raise RunEnd(
                RunState.FAILED, f"failed: node {slot.name} raised {reply.error.type}{where}"
            )
        raise RunEnd(RunState.FAILED, f"failed: {reply.reason}")

    def is_due(self, slot: NodeSlot, now_ns: int) -> bool:
        """Is the sleeping node to be woken at `now_ns`: its time has come, or a message it
        waits for (any, while spinning; or one of its wake_on topics) is there."""
        if slot.wake_at_ns is not None and slot.wake_at_ns <= now_ns:
            return True
        if slot.wake_on is None:
            return slot.wake_at_ns is None and self.bus.has_pending(slot.name)
        return self.bus.has_pending_on(slot.name, slot.wake_on)

    def listens(self, slot: NodeSlot) -> bool:
        """Can a message wake this node before its wake time (so the clock must stop at the
        robot's next publication)?"""
        return slot.wake_at_ns is None or slot.wake_on is not None

    def poll_finishing(self) -> None:
        """Collect the Exited of nodes that are finishing (or end them past their budget)."""
        for slot in self.slots.values():
            if slot.finishing and slot.process is not None:
                exited = slot.process.poll_finished()
                if exited is not None:
                    self.handle_reply(slot, exited)

    def wake(self, slot: NodeSlot, time_ns: int) -> None:
        """Lockstep: wake one node now and handle its reply."""
        self.begin_wake(slot, time_ns)
        self.handle_reply(slot, slot.process.poll_reply(None))

    def begin_wake(self, slot: NodeSlot, time_ns: int) -> None:
        deliveries, newest_sensor_s = self.bus.take(slot.name)
        if newest_sensor_s is not None:
            slot.newest_sensor_s = newest_sensor_s
        if slot.last_wake_ns is not None:
            slot.metrics.period.add((time_ns - slot.last_wake_ns) / NS)
        slot.last_wake_ns = time_ns
        slot.metrics.wakes += 1
        slot.woken_at_wall = time.perf_counter()
        graph = None
        if slot.graph_version != self.bus.version:
            graph, slot.graph_version = self.bus.graph_topics(), self.bus.version
        slot.process.begin_wake(time_ns / NS, deliveries, graph)

    def _from_node(self, slot: NodeSlot, published: list[Envelope]) -> None:
        now_s = self.time_ns / NS
        for envelope in published:
            slot.metrics.published += 1
            self.bus.publish(slot.name, envelope, now_s)
            self.record(envelope.topic, envelope.type, self.time_ns, envelope.data)
            if self.sim.robot.commands.get(envelope.topic) is not None:
                self._command_robot(slot, envelope)
            if self.builtins:
                self.builtins.deliver_envelope(self, slot.name, envelope)

    def _command_robot(self, slot: NodeSlot, envelope: Envelope) -> None:
        if self.faults.motors_stalled():
            return
        try:
            ros1_type = self.sim.robot.commands[envelope.topic][0]._type
            message = self.dialect.command(
                slot.name, envelope, ros1_type, lambda line: self._log_lines(slot, [line])
            )
            if message is None:  # a type the topic does not take (said once in the log)
                slot.metrics.rejected_commands += 1
                return
            self.sim.apply(envelope.topic, message)
        except (SimulationError, CommandError, ValueError) as error:
            slot.metrics.rejected_commands += 1
            self._log_lines(slot, [f"[robot] rejected {envelope.topic}: {error}"])
            return
        if slot.newest_sensor_s is not None:
            slot.metrics.latency.add(self.time_ns / NS - slot.newest_sensor_s)

    def _from_robot(self, topic: str, message: object, time_s: float) -> None:
        envelope = self.dialect.envelope(topic, message)
        self.record(topic, envelope.type, round(time_s * NS), envelope.data)
        if self.faults.active:
            self.faults.expire(self.time_ns)
            envelope = self.faults.filter(envelope)
            if envelope is None:
                return
        self.bus.publish(ROBOT, envelope, time_s)

    def _command_zero(self) -> None:
        """Every end (finished, crashed, stopped, server shutdown) leaves the robot commanded
        to zero velocity, recorded as the run's last command, as a real robot needs."""
        if self.sim is None or self.recorder is None:
            return
        if self.backend is not None:  # a real robot stops at once, not down a ramp
            try:
                self.backend.stop()
            except Exception:
                log.exception("run %s: could not stop the robot", self.run_id)
        for name, (msg_type, _) in self.sim.robot.commands.items():
            if msg_type._type != "geometry_msgs/Twist":
                continue
            try:
                if self.backend is None:  # a real robot was stopped above
                    self.sim.apply(name, msg_type())
                zero_type, data = self.dialect.zero_command(name, msg_type, self.time_ns)
                self.record(name, zero_type, self.time_ns, data)
            except Exception:  # the end must go on whatever the robot says
                log.exception("run %s: could not command zero velocity on %s", self.run_id, name)

    def _stall_motors(self) -> None:
        for name, (msg_type, _) in self.sim.robot.commands.items():
            if msg_type._type == "geometry_msgs/Twist":
                self.sim.apply(name, msg_type())

    def _publish_goal(self, x: float, y: float, yaw: float) -> None:
        goal = PoseStamped(
            header=Header(stamp=Time.from_sec(self.time_ns / NS), frame_id="map"),
            pose=Pose(
                position=Point(x=x, y=y),
                orientation=Quaternion(z=math.sin(yaw / 2), w=math.cos(yaw / 2)),
            ),
        )
        envelope = self.dialect.envelope(GOAL_TOPIC, goal)
        self.bus.publish(RUN, envelope, self.time_ns / NS)
        self.record(GOAL_TOPIC, envelope.type, self.time_ns, envelope.data)

    @property
    def velocity_topic(self) -> str | None:
        """The robot's Twist command topic (Control, cmd_vel), if it has one."""
        return next(
            (
                t.name
                for t in self.sim.topics
                if t.direction is Direction.SUBSCRIBE and t.type_name == "geometry_msgs/Twist"
            ),
            None,
        )

    # ----------------------------------------------------------------------------- built-ins
    @property
    def time_s(self) -> float:
        return self.time_ns / NS

    def next_builtin_ns(self) -> int | None:
        return self.builtins.next_ns()

    def next_tf_ns(self) -> int | None:
        """When /tf is next due, if a node listens to it (then the clocks stop there, so a
        tf listener gets the tree at 30 Hz in lockstep too); None if nobody listens."""
        return self._next_tf_ns if self.bus.has_subscribers(TF_TOPIC) else None

    # ----------------------------------------------------------------------------- simulation
    def advance_to(self, time_ns: int) -> None:
        """Step the robot to run time `time_ns`, routing what it publishes."""
        if time_ns > self.time_ns:
            try:
                published = self.sim.step((time_ns - self.time_ns) / NS)
            except SimulationError as error:
                if self.backend is not None:
                    raise RunEnd(RunState.FAILED, f"failed: {error}") from None
                raise RunEnd(RunState.FAILED, f"failed: the simulation stopped: {error}") from None
            self.time_ns = time_ns
            for item in published:
                self._from_robot(item.topic, item.message, item.time_s)
            for event in self.sim.drain_events():
                if event.kind is EventKind.LEFT_BOUNDS:
                    log.debug("run %s: robot left the bounds at %.3f s", self.run_id, event.time_s)
        while self._script and round(self._script[0][0] * NS) <= self.time_ns:
            _, command = self._script.pop(0)
            self._apply_command(command)
        if self.builtins:
            self.builtins.tick(self)
        if self._finishing_nodes():
            self.poll_finishing()
        if self.backend is not None:
            self._emit_logs("robot", self.backend.take_logs())  # the robot's own loginfo
        self._check_robot()
        if self.time_ns >= self._next_tf_ns:
            self._record_tf()
        if self.recorder.error:
            raise RunEnd(RunState.FAILED, f"failed: {self.recorder.error}")

    def _finishing_nodes(self) -> bool:
        return any(slot.finishing for slot in self.slots.values())

    def next_script_ns(self) -> int | None:
        """Run time of the next scripted control, if any (the clocks stop there)."""
        return round(self._script[0][0] * NS) if self._script else None

    def _check_robot(self) -> None:
        pose = self.sim.state.pose
        min_x, min_y, max_x, max_y = self.sim.world.bounds
        margin = MAP_MARGIN_M
        if not (
            min_x - margin <= pose.x <= max_x + margin
            and min_y - margin <= pose.y <= max_y + margin
        ):
            raise RunEnd(RunState.FAILED, "failed: robot left the map")

    def _record_tf(self) -> None:
        pose = self.sim.state.pose
        origin = self.sim.odometry_origin
        message = tf_message(
            self.time_ns,
            pose.x,
            pose.y,
            pose.yaw,
            self.sim.robot.sensor_frames(self.sim.state),
            odom_origin=(origin.x, origin.y, origin.yaw),
        )
        envelope = self.dialect.envelope(TF_TOPIC, message)
        self.record(TF_TOPIC, envelope.type, self.time_ns, envelope.data)
        # Nodes see the same tree on "tf" (tf2_ros.TransformListener subscribes to it).
        self.bus.publish(RUN, envelope, self.time_ns / NS)
        self._next_tf_ns = self.time_ns + TF_PERIOD_NS
