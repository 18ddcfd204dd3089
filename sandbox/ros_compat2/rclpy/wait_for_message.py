"""rclpy.wait_for_message.wait_for_message (rclpy/wait_for_message.py): the next message on a
topic, without spinning the node's other callbacks."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from sandbox.ros_errors import RunEndedInterrupt

from . import _state

if TYPE_CHECKING:
    from .node import Node
    from .qos import QoSProfile


def wait_for_message(
    msg_type: Any,
    node: Node,
    topic: str,
    *,
    qos_profile: QoSProfile | int = 1,
    time_to_wait: float = -1,
) -> tuple[bool, Any]:
    """(True, message) for the next message on `topic`, or (False, None) after `time_to_wait`
    seconds (negative: no limit) or when the run ends the node."""
    subscription = node.create_subscription(msg_type, topic, lambda _: None, qos_profile)
    deadline_ns = None if time_to_wait < 0 else _state.now_ns() + int(time_to_wait * 1e9)
    try:
        while not subscription._ready():
            if deadline_ns is not None and _state.now_ns() >= deadline_ns:
                return False, None
            try:
                _state.wait(deadline_ns, subscription._wake_topics())
            except RunEndedInterrupt:
                return False, None
        message, _ = subscription._queue.popleft()
        return True, message
    finally:
        node.destroy_subscription(subscription)
