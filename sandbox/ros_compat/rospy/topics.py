"""Publisher, Subscriber and wait_for_message (rospy.topics look-alikes).

Publishing queues the message; it leaves the node at the next sleep. Callbacks run inside
sleep()/spin(), in delivery order, with the message deserialized as the declared class.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from sandbox import runtime as _runtime
from sandbox.msgs import Message
from sandbox.runtime import ROSException

from .timing import duration_ns


class Publisher:
    def __init__(
        self,
        name: str,
        data_class: type[Message],
        subscriber_listener: Any = None,
        tcp_nodelay: bool = False,
        latch: bool = False,
        headers: Any = None,
        queue_size: int | None = None,
    ) -> None:
        # As rospy: a Publisher may be made before init_node(); it is registered when the node
        # first sleeps (what it publishes before init_node() is refused, as in rospy).
        node = _runtime.current()
        self._node = node
        if getattr(data_class, "_type", None) == "*":
            raise ROSException(
                f"rospy.Publisher('{name}', AnyMsg): publish with the message class of the "
                "topic; AnyMsg is for subscribing without decoding"
            )
        if queue_size is not None and (
            not isinstance(queue_size, int) or isinstance(queue_size, bool) or queue_size < 0
        ):
            raise ROSException(f"queue_size must be a non-negative integer, got {queue_size!r}")
        self.queue_size = queue_size
        self.name = node.advertise(name, data_class, latch=bool(latch))
        self.resolved_name = "/" + self.name
        self.data_class = data_class
        self.type = data_class._type
        self._registered = True

    def _build(self, args: tuple[Any, ...], kwargs: dict[str, Any]) -> Message:
        expected = self.data_class
        if len(args) == 1 and not kwargs and isinstance(args[0], Message):
            message = args[0]
            if type(message) is not expected:
                raise ROSException(
                    f"publish() on '{self.name}' expects {expected._type}, got {message._type}"
                )
            return message
        if not args and not kwargs:
            raise ROSException(
                f"publish() on '{self.name}' needs a message, "
                f"e.g. pub.publish({expected.__name__}())"
            )
        try:
            return expected(*args, **kwargs)
        except (TypeError, ValueError) as error:
            given = ", ".join([repr(a) for a in args] + [f"{k}={v!r}" for k, v in kwargs.items()])
            raise ROSException(
                f"publish() on '{self.name}' expects a {expected._type}; could not build one "
                f"from ({given}): {error}"
            ) from None

    def publish(self, *args: Any, **kwargs: Any) -> None:
        """Publish a message, or build one from field values: pub.publish(5) -> Int32(5)."""
        if not self._registered:
            raise ROSException("publish() to an unregistered() handle")
        if self._node.node_name is None:
            raise ROSException(
                "ROS node has not been initialized yet. Please call init_node() first"
            )
        self._node.publish(self.name, self._build(args, kwargs), self.queue_size)

    def get_num_connections(self) -> int:
        """Subscribers of the topic in the run (the robot counts for its command topics)."""
        return _connections(self._node, self.name, "subscribers")

    def unregister(self) -> None:
        self._registered = False


class Subscriber:
    def __init__(
        self,
        name: str,
        data_class: type[Message],
        callback: Callable[..., Any] | None = None,
        callback_args: Any = None,
        queue_size: int | None = None,
        buff_size: int = 65536,
        tcp_nodelay: bool = False,
    ) -> None:
        node = _runtime.current()  # may come before init_node(), as in rospy
        if callback is not None and not callable(callback):
            raise TypeError(
                f"rospy.Subscriber('{name}', ...): callback must be a function, got {callback!r}"
            )
        self._node = node
        if queue_size is not None and (
            not isinstance(queue_size, int) or isinstance(queue_size, bool) or queue_size == 0
        ):
            raise ROSException(f"queue size must be a positive integer, got {queue_size!r}")
        self._subscription = node.subscribe(
            name, data_class, callback, callback_args, None if queue_size == -1 else queue_size
        )
        self.name = self._subscription.topic
        self.resolved_name = "/" + self.name
        self.data_class = data_class
        self.type = data_class._type
        self.callback = callback
        self.callback_args = callback_args

    def get_num_connections(self) -> int:
        """Publishers of the topic in the run (the robot counts for its sensor topics)."""
        return _connections(self._node, self.name, "publishers")

    def unregister(self) -> None:
        self._node.unsubscribe(self._subscription)


def _connections(node: _runtime.NodeRuntime, topic: str, side: str) -> int:
    # `while pub.get_num_connections() < 1: pass` is a busy loop waiting for the graph
    node.poll()
    me = (node.info.node_name or "").strip("/")
    for entry in node.graph or ():
        if entry.name == topic:
            return sum(1 for name in getattr(entry, side) if name != me)
    robot = node.robot_direction(topic)
    wanted = "subscribe" if side == "subscribers" else "publish"
    return 1 if robot == wanted else 0


def wait_for_message(topic: str, topic_type: type[Message], timeout: float | None = None) -> Any:
    """Sleep until the next message on `topic` arrives and return it."""
    node = _runtime.current()
    node.require_init("rospy.wait_for_message()")
    received: list[Message] = []
    subscription = node.subscribe(topic, topic_type, received.append)
    deadline = None
    if timeout is not None:
        deadline = node.clock.now_ns() + duration_ns(timeout, "rospy.wait_for_message()")
    try:
        while not received:
            if deadline is not None and node.clock.now_ns() >= deadline:
                raise ROSException(
                    f"timeout exceeded while waiting for message on topic /{subscription.topic}"
                )
            # The first message on the topic wakes the node (rospy returns at once too).
            node.wait_until(deadline, wake_on=[subscription.topic])
    finally:
        node.unsubscribe(subscription)
    return received[0]


class SubscribeListener:
    """Base class for the `subscriber_listener` of a Publisher (rospy.SubscribeListener).

    Accepted so scripts that pass one run; its methods are not called here, because nodes of a
    run are not told when another node subscribes."""

    def peer_subscribe(self, topic_name: str, topic_publish: Any, peer_publish: Any) -> None:
        pass

    def peer_unsubscribe(self, topic_name: str, num_peers: int) -> None:
        pass


def get_published_topics(namespace: str = "/") -> list[list[str]]:
    """[[topic, type], ...] of the topics something in the run publishes (rospy's form: names
    with a leading slash), under `namespace`."""
    from sandbox.services import is_internal

    node = _runtime.current()
    graph = node.current_graph()
    prefix = "/" + namespace.strip("/")
    found = []
    for entry in graph:
        name = "/" + entry.name
        under = prefix == "/" or name == prefix or name.startswith(prefix + "/")
        if entry.publishers and not is_internal(entry.name) and under:
            found.append([name, entry.type])
    return sorted(found)
