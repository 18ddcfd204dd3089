"""The run's edge with its robot (a `RobotBackend`: the simulator or a real robot): what the
robot publishes goes onto the bus and into the outputs (through any injected fault), commands go
into it (a sandboxed node's checked and converted from the run's dialect, a built-in's trusted),
and the run's own messages about it - /tf, the goal pose - are made here. Every end of a run
leaves the robot commanded to zero velocity through `command_zero`.
"""

from __future__ import annotations

import logging

from sandbox.msgs import Time
from sandbox.msgs.geometry_msgs import Point, Pose, PoseStamped, Quaternion
from sandbox.msgs.std_msgs import Header
from sandbox.msgs.tf2_msgs import TFMessage
from sandbox.protocol import Envelope, RobotTopic
from sandbox.units import NS_PER_S
from server.runs.bus import ROBOT, RUN, TopicBus
from server.runs.dialect import Dialect
from server.runs.faults import Faults
from server.runs.outputs import RunOutputs
from server.runs.recorder import Recorder
from server.runs.result import RunEnd
from server.runs.slots import NodeSlot
from server.runs.state import RunState
from server.runs.tf import tf_message
from server.sim.backend import RobotBackend
from server.sim.geometry import yaw_quaternion
from server.sim.robots.base import CommandError
from server.sim.simulation import SimulationError

log = logging.getLogger("robodojo.runs")

GOAL_TOPIC = "goal"  # RViz's "2D Nav Goal" idea: the run publishes the goal pose here
TF_TOPIC = "tf"  # the transform tree, recorded and published to nodes (tf2_ros listens here)
TF_PERIOD_NS = NS_PER_S // 30  # [ns] /tf recorded at 30 Hz: smooth in Foxglove, small on disk
MAP_MARGIN_M = 0.5  # [m] beyond the world's bounds by this much, the robot left the map


class RobotEdge:
    def __init__(
        self,
        backend: RobotBackend,
        dialect: Dialect,
        bus: TopicBus,
        outputs: RunOutputs,
        faults: Faults,
        run_id: str,
    ) -> None:
        self.backend = backend
        self.dialect = dialect
        self.bus = bus
        self.outputs = outputs
        self.faults = faults
        self.run_id = run_id
        self.commands = backend.robot.commands  # topic -> (ROS 1 class, ...) the robot takes
        self.next_tf_ns = 0

    def declare(self, recorder: Recorder) -> None:
        """The robot's topics, the goal and /tf on the bus and in the recording."""
        dialect = self.dialect
        for topic in self.backend.topics:
            type_name = dialect.type_name(topic.type_name)
            if dialect.command_types(topic.type_name, topic.direction):  # Twist, TwistStamped
                self.bus.allow_types(topic.name, type_name)  # recorded in the type sent
                continue
            self.bus.declare_topic(topic.name, type_name, ROBOT if topic.rate_hz else None)
            recorder.add_topic(topic.name, type_name)
        for name, ros1_type in ((GOAL_TOPIC, PoseStamped._type), (TF_TOPIC, TFMessage._type)):
            self.bus.declare_topic(name, dialect.type_name(ros1_type), RUN)
            recorder.add_topic(name, dialect.type_name(ros1_type))

    def topics_for_nodes(self) -> list[RobotTopic]:
        """The robot's topics and the goal, as a node is told them (in the run's dialect)."""
        topics = [
            RobotTopic(
                t.name,
                self.dialect.type_name(t.type_name),
                str(t.direction),
                t.rate_hz,
                accepts=self.dialect.command_types(t.type_name, t.direction),
            )
            for t in self.backend.topics
        ]
        topics.append(RobotTopic(GOAL_TOPIC, self.dialect.type_name(PoseStamped._type), "publish"))
        return topics

    @property
    def velocity_topic(self) -> str | None:
        """The robot's Twist command topic (Control, cmd_vel), if it has one."""
        return next(iter(self.backend.robot.velocity_topics()), None)

    # ----------------------------------------------------------------------------- from it
    def from_robot(self, topic: str, message: object, time_s: float, now_ns: int) -> None:
        """A message the robot published at `time_s` [s]: recorded as it was, then onto the bus
        unless a fault drops or changes it."""
        envelope = self.dialect.envelope(topic, message)
        self.outputs.record(topic, envelope.type, round(time_s * NS_PER_S), envelope.data)
        if self.faults.active:
            self.faults.expire(now_ns)
            envelope = self.faults.filter(envelope)
            if envelope is None:
                return
        self.bus.publish(ROBOT, envelope, time_s)

    def check_in_map(self) -> None:
        pose = self.backend.state.pose
        if not self.backend.world.in_bounds(pose.x, pose.y, MAP_MARGIN_M):
            raise RunEnd(RunState.FAILED, "failed: robot left the map")

    # ----------------------------------------------------------------------------- into it
    def command_from_node(self, slot: NodeSlot, envelope: Envelope, now_ns: int) -> None:
        """A sandboxed node's command: converted from the run's dialect, refused with a line in
        the node's log when the type or the values are wrong (the run goes on)."""
        if self.faults.motors_stalled():
            return
        try:
            ros1_type = self.commands[envelope.topic][0]._type
            message = self.dialect.command(
                slot.name, envelope, ros1_type, lambda line: slot.log([line], self.outputs)
            )
            if message is None:  # a type the topic does not take (said once in the log)
                slot.metrics.rejected_commands += 1
                return
            self.backend.apply(envelope.topic, message)
        except (SimulationError, CommandError, ValueError) as error:
            slot.metrics.rejected_commands += 1
            slot.log([f"[robot] rejected {envelope.topic}: {error}"], self.outputs)
            return
        if slot.newest_sensor_s is not None:
            slot.metrics.latency.add(now_ns / NS_PER_S - slot.newest_sensor_s)

    def command_trusted(self, topic: str, message: object, native: bool) -> None:
        """A built-in's command, a ROS 1 object (or a ROS 2 one if `native`: a TwistStamped
        reaches a Twist topic as its twist). Trusted: a refusal is our bug and raises."""
        if self.faults.motors_stalled():
            return
        if native:
            message = self.dialect.to_ros1(message, self.commands[topic][0]._type)
        self.backend.apply(topic, message)

    def command_zero(self, now_ns: int) -> None:
        """Zero velocity now (a real robot stops at once, not down a ramp), recorded as the
        last command on each velocity topic in the type the nodes used there."""
        try:
            self.backend.stop()
        except Exception:  # the end must go on whatever the robot says
            log.exception("run %s: could not stop the robot", self.run_id)
        for name in self.backend.robot.velocity_topics():
            try:
                zero_type, data = self.dialect.zero_command(name, self.commands[name][0], now_ns)
                self.outputs.record(name, zero_type, now_ns, data)
            except Exception:
                log.exception("run %s: could not record zero velocity on %s", self.run_id, name)

    def stall_motors(self) -> None:
        """Zero on every velocity topic (the stall-motors fault; a real robot's LEDs stay)."""
        for name in self.backend.robot.velocity_topics():
            self.backend.apply(name, self.commands[name][0]())

    # ----------------------------------------------------------------------------- the run's own
    def publish_goal(self, x: float, y: float, yaw: float, now_ns: int) -> None:
        goal = PoseStamped(
            header=Header(stamp=Time.from_sec(now_ns / NS_PER_S), frame_id="map"),
            pose=Pose(
                position=Point(x=x, y=y),
                orientation=Quaternion(*yaw_quaternion(yaw)),
            ),
        )
        self._publish(GOAL_TOPIC, goal, now_ns)

    def tf_due_ns(self) -> int | None:
        """When /tf is next due, if a node listens to it (then the clocks stop there, so a
        tf listener gets the tree at 30 Hz in lockstep too); None if nobody listens."""
        return self.next_tf_ns if self.bus.has_subscribers(TF_TOPIC) else None

    def record_tf(self, now_ns: int) -> None:
        """The transform tree now, recorded and sent to nodes on "tf" (tf2_ros listens)."""
        state = self.backend.state
        pose, origin = state.pose, self.backend.odometry_origin
        message = tf_message(
            now_ns,
            pose.x,
            pose.y,
            pose.yaw,
            self.backend.robot.sensor_frames(state),
            odom_origin=(origin.x, origin.y, origin.yaw),
        )
        self._publish(TF_TOPIC, message, now_ns)
        self.next_tf_ns = now_ns + TF_PERIOD_NS

    def _publish(self, topic: str, message: object, now_ns: int) -> None:
        envelope = self.dialect.envelope(topic, message)
        self.bus.publish(RUN, envelope, now_ns / NS_PER_S)
        self.outputs.record(topic, envelope.type, now_ns, envelope.data)
