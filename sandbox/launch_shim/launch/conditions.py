"""Stand-in for `launch.conditions`."""

from sandbox.launch2.conditions import (
    IfCondition,
    LaunchConfigurationEquals,
    LaunchConfigurationNotEquals,
    UnlessCondition,
)
from sandbox.launch2.errors import InvalidConditionExpressionError
from sandbox.launch2.missing import missing

__all__ = [
    "IfCondition",
    "InvalidConditionExpressionError",
    "LaunchConfigurationEquals",
    "LaunchConfigurationNotEquals",
    "UnlessCondition",
]
__getattr__ = missing("launch.conditions")
