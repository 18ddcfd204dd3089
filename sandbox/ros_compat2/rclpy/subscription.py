"""rclpy.subscription.Subscription (rclpy/subscription.py): a queue its executor drains.

Messages for the subscription's topic are decoded when they arrive (at the node's wakes) and
wait in its queue, which keeps at most the QoS depth (KEEP_LAST; the oldest are dropped, as
rmw's history does); an executor that spins takes one message per callback. The callback takes
the message, or the message and a MessageInfo dict, as in rclpy.
"""

from __future__ import annotations

import inspect
from collections import deque
from collections.abc import Callable
from enum import Enum
from typing import TYPE_CHECKING, Any

from . import _state
from .event_handler import IncompatibleQoSReporter
from .exceptions import InvalidHandle
from .qos import (
    DurabilityPolicy,
    QoSPolicyKind,
    QoSProfile,
    ReliabilityPolicy,
    qos_policy_name_from_kind,
)

if TYPE_CHECKING:
    from .callback_groups import CallbackGroup
    from .node import Node


class Subscription:
    """Receives messages of one type on one topic (made by Node.create_subscription)."""

    class CallbackType(Enum):
        MessageOnly = 0
        WithMessageInfo = 1

    def __init__(
        self,
        node: Node,
        msg_type: type,
        topic: str,
        bus_topic: str,
        callback: Callable[..., Any],
        callback_group: CallbackGroup,
        qos_profile: QoSProfile,
        raw: bool = False,
        event_callbacks: Any = None,
    ) -> None:
        self.msg_type = msg_type
        self._incompatible_qos = IncompatibleQoSReporter(
            event_callbacks, self._default_incompatible_qos
        )
        self.topic = topic
        self.callback = callback
        self.callback_group = callback_group
        self.qos_profile = qos_profile
        self.raw = raw
        self._node = node
        self._bus_topic = bus_topic
        self._queue: deque[tuple[Any, dict[str, int]]] = deque(maxlen=qos_profile.queue_limit())
        self._received = 0
        self._destroyed = False
        self._warned_publishers: set[str] = set()
        self._reliable = qos_profile.effective_reliability() == ReliabilityPolicy.RELIABLE
        self._runtime_subscription = _state.runtime().subscribe(
            bus_topic,
            msg_type,
            self._arrived,
            best_effort=qos_profile.effective_reliability() == ReliabilityPolicy.BEST_EFFORT,
            transient_local=self.transient_local,
            volatile=not self.transient_local,
        )

    @property
    def handle(self) -> Subscription:
        if self._destroyed:
            raise InvalidHandle("the subscription was destroyed")
        return self

    @property
    def topic_name(self) -> str:
        return "/" + self._bus_topic

    @property
    def callback(self) -> Callable[..., Any]:
        return self._callback

    @callback.setter
    def callback(self, value: Callable[..., Any]) -> None:
        self._callback = value
        self._callback_type = Subscription.CallbackType.MessageOnly
        try:
            inspect.signature(value).bind(object())
            return
        except TypeError:
            pass
        except ValueError:
            return  # a builtin without a signature: called with the message
        try:
            inspect.signature(value).bind(object(), object())
            self._callback_type = Subscription.CallbackType.WithMessageInfo
            return
        except TypeError:
            pass
        raise RuntimeError(
            "Subscription.__init__(): callback should be either be callable with one argument"
            "(to get only the message) or two (to get message and message info)"
        )

    def get_publisher_count(self) -> int:
        return self._node._count_on_graph(self._bus_topic, subscribers=False)

    def destroy(self) -> None:
        if not self._destroyed:
            self._destroyed = True
            self._queue.clear()
            _state.runtime().unsubscribe(self._runtime_subscription)

    def __enter__(self) -> Subscription:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self._node.destroy_subscription(self)

    @property
    def transient_local(self) -> bool:
        return self.qos_profile.effective_durability() == DurabilityPolicy.TRANSIENT_LOCAL

    # ------------------------------------------------------------------ arrivals
    def _arrived(self, message: Any) -> None:
        """A message from the run's bus (decoded by the runtime), unless this subscription's
        QoS keeps it out: a latched topic's history reaches only a TRANSIENT_LOCAL
        subscription, and a BEST_EFFORT publisher's messages do not reach a RELIABLE one."""
        node_runtime = _state.runtime()
        envelope = node_runtime.delivering
        if envelope is not None:
            if envelope.replayed and not self.transient_local:
                return
            if envelope.publisher and self._reliable:
                graph = {topic.name: topic for topic in node_runtime.graph or ()}
                topic = graph.get(self._bus_topic)
                if topic is not None and envelope.publisher in topic.best_effort_publishers:
                    self._warn_incompatible(envelope.publisher, QoSPolicyKind.RELIABILITY)
                    return
        self._put(message)

    def _put(self, message: Any) -> None:
        if self._destroyed:
            return
        self._received += 1
        now = _state.now_ns()
        info = {
            "source_timestamp": now,
            "received_timestamp": now,
            "publication_sequence_number": self._received,
            "reception_sequence_number": self._received,
        }
        self._queue.append((message, info))

    def _warn_incompatible(self, publisher_name: str, policy_kind: int) -> None:
        if publisher_name in self._warned_publishers:
            return
        self._warned_publishers.add(publisher_name)
        self._incompatible_qos.report(policy_kind)

    def _default_incompatible_qos(self, policy_kind: int) -> None:
        """rclpy's default callback for the event (rclpy/event_handler.py)."""
        self._node.get_logger().warning(
            f"New publisher discovered on topic '{self.topic_name}', offering incompatible QoS. "
            "No messages will be received from it. Last incompatible policy: "
            f"{qos_policy_name_from_kind(policy_kind)}"
        )

    def _check_graph(self, topic: Any, own_label: str) -> None:
        """The run's graph changed: warn about other nodes' publishers whose QoS keeps their
        messages from this subscription (the run's bus does not deliver them)."""
        for publisher in topic.publishers:
            if publisher == own_label:
                continue
            if self._reliable and publisher in topic.best_effort_publishers:
                self._warn_incompatible(publisher, QoSPolicyKind.RELIABILITY)
            elif self.transient_local and publisher not in topic.latched_publishers:
                self._warn_incompatible(publisher, QoSPolicyKind.DURABILITY)

    # ------------------------------------------------------------------ executor side
    def _ready(self) -> bool:
        return not self._destroyed and bool(self._queue)

    def _due_ns(self) -> int | None:
        return None

    def _wake_topics(self) -> set[str]:
        return set() if self._destroyed else {self._bus_topic}

    def _take(self) -> Callable[[], Any] | None:
        if not self._queue:
            return None
        message, info = self._queue.popleft()
        if self.raw:
            message = message.serialize()
        callback = self._callback
        if self._callback_type is Subscription.CallbackType.WithMessageInfo:
            return lambda: callback(message, info)
        return lambda: callback(message)
