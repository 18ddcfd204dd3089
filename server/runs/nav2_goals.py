"""The goal bookkeeping of an action server now lives in sandbox/action_goals.py, shared by the
built-in Nav2 server and the sandbox's rclpy.action (server modules may import sandbox; the
sandbox never imports server). Kept so existing imports work; import sandbox.action_goals."""

from sandbox.action_goals import (
    ZERO_UUID,
    ActionGoals,
    CancelCode,
    Goal,
    GoalEvent,
    GoalStatus,
    GoalTransitionError,
)

__all__ = [
    "ZERO_UUID",
    "ActionGoals",
    "CancelCode",
    "Goal",
    "GoalEvent",
    "GoalStatus",
    "GoalTransitionError",
]
