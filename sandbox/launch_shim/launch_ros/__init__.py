"""Stand-in for ROS 2's `launch_ros` package (sandbox/launch_shim/README.md)."""

from launch_ros import actions, descriptions, parameter_descriptions, substitutions
from sandbox.launch2.missing import missing

__all__ = ["actions", "descriptions", "parameter_descriptions", "substitutions"]
__getattr__ = missing("launch_ros")
