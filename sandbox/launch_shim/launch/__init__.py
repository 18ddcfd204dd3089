"""Stand-in for ROS 2's `launch` package (sandbox/launch_shim/README.md)."""

from launch import actions, conditions, launch_description_sources, substitutions
from sandbox.launch2.actions import Action, LaunchDescription, LaunchDescriptionEntity
from sandbox.launch2.conditions import Condition
from sandbox.launch2.context import LaunchContext
from sandbox.launch2.missing import missing
from sandbox.launch2.substitutions import Substitution

__all__ = [
    "Action",
    "Condition",
    "LaunchContext",
    "LaunchDescription",
    "LaunchDescriptionEntity",
    "Substitution",
    "actions",
    "conditions",
    "launch_description_sources",
    "substitutions",
]
__getattr__ = missing("launch")
