"""What an rclpy action server and client share: rcl_action's names under `<action>/_action/`,
the QoS of its status topic, goal ids, and running a callback that may be a coroutine.

Sources (facts): rcl_action (names.c: `<action>/_action/send_goal`, `get_result`, `cancel_goal`,
`feedback`, `status`; rcl_action_qos_profile_status_default: depth 1, reliable, transient
local), action_msgs/msg/GoalStatus (the status numbers), rclpy/action/*.py (uuid4 goal ids).
"""

from __future__ import annotations

import uuid
from typing import Any

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from sandbox.action_goals import GoalStatus
from sandbox.msgs import get_message_class

FEEDBACK_DEPTH = 10  # [messages] rclpy's default feedback publisher/subscription depth
TERMINAL = (GoalStatus.SUCCEEDED, GoalStatus.CANCELED, GoalStatus.ABORTED)


def names(action_name: str) -> dict[str, str]:
    """The services and topics of one action, as rcl_action names them."""
    base = f"{action_name}/_action/"
    return {part: base + part for part in ("send_goal", "get_result", "cancel_goal",
                                           "feedback", "status")}  # fmt: skip


def status_qos() -> QoSProfile:
    """rcl_action_qos_profile_status_default: the last status array reaches late joiners."""
    return QoSProfile(
        depth=1,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )


def new_goal_id() -> Any:
    """A random unique_identifier_msgs/msg/UUID, as rclpy's ActionClient makes one per goal."""
    return get_message_class("unique_identifier_msgs/msg/UUID")(uuid=list(uuid.uuid4().bytes))


def uuid_bytes(goal_id: Any) -> bytes:
    return bytes(bytearray(int(value) for value in goal_id.uuid))


def check_action_type(action_type: Any, who: str) -> None:
    if not (hasattr(action_type, "Goal") and hasattr(action_type, "Impl")):
        raise TypeError(
            f"{who} takes an action type such as Fibonacci (from "
            "example_interfaces.action import Fibonacci) or NavigateToPose, got "
            f"{action_type!r}"
        )


def run_callback(callback: Any, *args: Any) -> Any:
    """callback(*args); a coroutine it returns is run to its end here (rclpy's
    await_or_execute, for an async callback that does not wait on a future)."""
    result = callback(*args)
    if hasattr(result, "send") and hasattr(result, "throw"):
        try:
            while True:
                result.send(None)
        except StopIteration as done:
            return done.value
    return result


def child_logger(node: Any, name: str) -> Any:
    logger = node.get_logger()
    get_child = getattr(logger, "get_child", None)
    return get_child(name) if get_child is not None else logger
