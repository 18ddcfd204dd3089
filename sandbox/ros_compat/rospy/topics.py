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
        node = _runtime.current()
        node.require_init("rospy.Publisher()")
        self._node = node
        self.name = node.advertise(name, data_class)
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
            raise ROSException(f"publish() on '{self.name}' after unregister()")
        self._node.publish(self.name, self._build(args, kwargs))

    def get_num_connections(self) -> int:
        return 1  # the robot (or the run) always listens

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
        node = _runtime.current()
        node.require_init("rospy.Subscriber()")
        if callback is not None and not callable(callback):
            raise TypeError(
                f"rospy.Subscriber('{name}', ...): callback must be a function, got {callback!r}"
            )
        self._node = node
        self._subscription = node.subscribe(name, data_class, callback, callback_args)
        self.name = self._subscription.topic
        self.resolved_name = "/" + self.name
        self.data_class = data_class
        self.type = data_class._type
        self.callback = callback
        self.callback_args = callback_args

    def get_num_connections(self) -> int:
        return 1

    def unregister(self) -> None:
        self._node.unsubscribe(self._subscription)


def wait_for_message(topic: str, topic_type: type[Message], timeout: float | None = None) -> Any:
    """Sleep until the next message on `topic` arrives and return it."""
    node = _runtime.current()
    node.require_init("rospy.wait_for_message()")
    received: list[Message] = []
    subscription = node.subscribe(topic, topic_type, received.append)
    deadline = None
    if timeout is not None:
        seconds = timeout.to_sec() if hasattr(timeout, "to_sec") else float(timeout)
        deadline = node.clock.now_ns() + round(seconds * 1e9)
    try:
        while not received:
            if deadline is not None and node.clock.now_ns() >= deadline:
                raise ROSException(
                    f"timeout exceeded while waiting for message on topic {subscription.topic}"
                )
            node.wait_until(deadline)
    finally:
        node.unsubscribe(subscription)
    return received[0]
