"""The robot's edge: the run presents its robot in the run's ROS dialect, as a driver would.

The simulator, the sensors, /tf and the built-in nodes keep their ROS 1 message classes
(sandbox.msgs). In a ROS 1 run nothing changes at the edge. In a ROS 2 run (spec.ros_version
== 2, docs/architecture.md "ROS 2") the robot looks the way a ROS 2 driver of it would: the same
topic names, frames and rates, ROS 2 type names ("sensor_msgs/msg/LaserScan") and CDR bytes
(with the 4-byte encapsulation header, as rclpy.serialization.serialize_message gives them):

- what leaves the robot or the run (sensor messages, /tf, the goal, a built-in's messages) is
  converted with `sandbox.msgs2.bridge.to_ros2` and serialized to CDR;
- what a node commands (a CDR envelope) is decoded and converted with `to_ros1` for
  `Simulation.apply`. A Twist command topic also takes geometry_msgs/msg/TwistStamped: ROS 2
  Jazzy's TurtleBot3 bringup subscribes cmd_vel as TwistStamped (turtlebot3_node's
  `enable_stamped_cmd_vel`), so nav2 and teleop there send it. Any other type is said once in
  the node's log and ignored, as a driver ignores a publisher whose type does not match.

The zero command at every end is sent in the type the nodes last used on that topic, so a
recording of a TwistStamped controller ends with a TwistStamped. Faults act on the envelopes
after this conversion, so they are dialect-blind.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from sandbox.msgs import Time, get_message_class
from sandbox.protocol import Envelope

TWIST = "geometry_msgs/Twist"
TWIST_STAMPED = "geometry_msgs/TwistStamped"


class Dialect:
    """One run's edge between the robot (ROS 1 objects) and its nodes (the run's dialect)."""

    def __init__(self, ros_version: int) -> None:
        if ros_version not in (1, 2):
            raise ValueError(f"ros_version must be 1 or 2, got {ros_version!r}")
        self.ros_version = ros_version
        self._last_type: dict[str, str] = {}  # command topic -> type of the last accepted command
        self._said: set[tuple[str, str, str]] = set()  # (node, topic, type) already logged
        if ros_version == 2:
            from sandbox.msgs2 import bridge

            self._bridge = bridge

    @property
    def ros2(self) -> bool:
        return self.ros_version == 2

    # ----------------------------------------------------------------------------- names
    def type_name(self, ros1_type: str) -> str:
        """The run's name of a ROS 1 type: itself, or "pkg/msg/Name" in a ROS 2 run."""
        return self._bridge.ros2_name(ros1_type) if self.ros2 else ros1_type

    def accepted_types(self, ros1_type: str) -> tuple[str, ...]:
        """The types a command topic of ROS 1 type `ros1_type` takes in this run."""
        if not self.ros2:
            return (ros1_type,)
        if ros1_type == TWIST:
            return (self.type_name(TWIST), self.type_name(TWIST_STAMPED))
        return (self.type_name(ros1_type),)

    def command_types(self, ros1_type: str, direction: str) -> list[str]:
        """`RobotTopic.accepts` of one robot topic: every type it takes when that is more than
        one (the sandbox then lets a node publish any of them), else []."""
        accepted = self.accepted_types(ros1_type) if str(direction) == "subscribe" else ()
        return list(accepted) if len(accepted) > 1 else []

    # ----------------------------------------------------------------------------- outgoing
    def envelope(self, topic: str, message: Any) -> Envelope:
        """A ROS 1 message of the robot, the run or a built-in as the nodes receive it."""
        if not self.ros2:
            return Envelope(topic, message._type, message.serialize())
        converted = self._bridge.to_ros2(message)
        return Envelope(topic, converted._type, converted.serialize())

    def to_ros2(self, message: Any) -> Any:
        return self._bridge.to_ros2(message)

    def to_ros1(self, message: Any, ros1_type: str | None = None) -> Any:
        return self._bridge.to_ros1(message, ros1_type)

    # ----------------------------------------------------------------------------- incoming
    def decode(self, envelope: Envelope) -> Any:
        """The message of a node's envelope, in the run's dialect."""
        return get_message_class(envelope.type).deserialize(envelope.data)

    def command(
        self, node: str, envelope: Envelope, ros1_type: str, say: Callable[[str], None]
    ) -> Any | None:
        """A node's command on a robot topic of ROS 1 type `ros1_type`, as the ROS 1 message
        `Simulation.apply` takes; None for a type the topic does not take (said once per node,
        topic and type through `say`). Malformed bytes raise ValueError, as today."""
        if not self.ros2:
            return get_message_class(envelope.type).deserialize(envelope.data)
        accepted = self.accepted_types(ros1_type)
        if envelope.type not in accepted:
            key = (node, envelope.topic, envelope.type)
            if key not in self._said:
                self._said.add(key)
                say(
                    f"[robot] '{envelope.topic}' takes {' or '.join(accepted)}, not "
                    f"{envelope.type}; the robot ignores these messages (publish one of those "
                    "types)"
                )
            return None
        message = get_message_class(envelope.type).deserialize(envelope.data)
        self._last_type[envelope.topic] = envelope.type
        return self._bridge.to_ros1(message, ros1_type)

    def zero_command(self, topic: str, ros1_class: type, time_ns: int) -> tuple[str, bytes]:
        """(type name, bytes) of the zero velocity the run sends at its end on `topic`, in the
        type the nodes last commanded with there."""
        zero = ros1_class()
        if not self.ros2:
            return zero._type, zero.serialize()
        if self._last_type.get(topic) == self.type_name(TWIST_STAMPED):
            stamped_class = get_message_class(TWIST_STAMPED)
            zero = stamped_class(twist=zero)
            zero.header.stamp = Time.from_nsec(int(time_ns))
        converted = self._bridge.to_ros2(zero)
        return converted._type, converted.serialize()
