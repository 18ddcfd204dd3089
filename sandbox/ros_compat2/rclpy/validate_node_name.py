"""rclpy.validate_node_name (rmw's rules, sandbox/ros2_names.py)."""

from __future__ import annotations

from sandbox.ros2_names import Ros2NameError
from sandbox.ros2_names import validate_node_name as _validate

from .exceptions import InvalidNodeNameException


def validate_node_name(node_name: str) -> bool:
    try:
        _validate(node_name)
    except Ros2NameError as error:
        raise InvalidNodeNameException(error.name, error.reason, error.index) from None
    return True
