"""rclpy.publisher.Publisher (rclpy/publisher.py) over the node's outbox.

publish() checks the message's class (TypeError as rclpy), serializes it (CDR) and queues it
for the node's next yield (sandbox.runtime.NodeRuntime.publish); subscriptions of the same
process get their own copy at once, since the run's bus never routes a node's message back to
it. A TRANSIENT_LOCAL publisher's topic is latched: later TRANSIENT_LOCAL subscribers get its
last message. After the run ended the node, publish() still reaches the run with the node's
last frame (in ROS 2 the context is invalid after SIGINT and publish raises; a run's end is
not the student's doing, and the usual "stop the robot" publish should not fail).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from sandbox.protocol import Envelope

from . import _state
from .event_handler import IncompatibleQoSReporter
from .exceptions import InvalidHandle
from .qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy, qos_policy_name_from_kind

if TYPE_CHECKING:
    from .node import Node


class Publisher:
    """Sends messages of one type on one topic (made by Node.create_publisher)."""

    def __init__(
        self,
        node: Node,
        msg_type: type,
        topic: str,
        bus_topic: str,
        qos_profile: QoSProfile,
        event_callbacks: Any = None,
    ) -> None:
        self.msg_type = msg_type
        self._incompatible_qos = IncompatibleQoSReporter(
            event_callbacks, self._default_incompatible_qos
        )
        self.topic = topic  # as given
        self.qos_profile = qos_profile
        self._node = node
        self._full_name = "/" + bus_topic
        self._bus_topic = bus_topic
        self._destroyed = False
        self._last: Any = None  # TRANSIENT_LOCAL: the last message, for late local subscribers
        self.reliability = qos_profile.effective_reliability()
        self.durability = qos_profile.effective_durability()
        latch = self.durability == DurabilityPolicy.TRANSIENT_LOCAL
        _state.runtime().advertise(bus_topic, msg_type, latch=latch, best_effort=self.best_effort)

    @property
    def handle(self) -> Publisher:
        if self._destroyed:
            raise InvalidHandle("the publisher was destroyed")
        return self

    @property
    def topic_name(self) -> str:
        return self._full_name

    def publish(self, msg: Any) -> None:
        """Send `msg` (an instance of the publisher's type, or its serialized bytes)."""
        if self._destroyed:
            raise InvalidHandle("publish() on a publisher that was destroyed")
        if isinstance(msg, bytes | bytearray):
            msg = self.msg_type.deserialize(bytes(msg))
        elif not isinstance(msg, self.msg_type):
            raise TypeError(f"Expected {self.msg_type}, got {type(msg)}")
        node_runtime = _state.runtime()
        if node_runtime.shutdown is not None and node_runtime.shutdown.by_parent:
            node_runtime.outbox.add(Envelope(self._bus_topic, msg._type, msg.serialize()), None)
        else:
            node_runtime.publish(self._bus_topic, msg)
        if self.durability == DurabilityPolicy.TRANSIENT_LOCAL:
            self._last = msg
        _state.state().deliver_locally(self, msg)

    def _default_incompatible_qos(self, policy_kind: int) -> None:
        """rclpy's default callback for the event (rclpy/event_handler.py)."""
        self._node.get_logger().warning(
            f"New subscription discovered on topic '{self.topic_name}', requesting incompatible "
            "QoS. No messages will be sent to it. Last incompatible policy: "
            f"{qos_policy_name_from_kind(policy_kind)}"
        )

    def get_subscription_count(self) -> int:
        return self._node._count_on_graph(self._bus_topic, subscribers=True)

    def destroy(self) -> None:
        self._destroyed = True

    def assert_liveliness(self) -> None:
        pass

    def wait_for_all_acked(self, timeout: Any = None) -> bool:
        return True  # nothing is ever unacknowledged on the run's bus

    def __enter__(self) -> Publisher:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._node.destroy_publisher(self)

    @property
    def best_effort(self) -> bool:
        return self.reliability == ReliabilityPolicy.BEST_EFFORT
