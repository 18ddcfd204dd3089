"""rclpy.validate_namespace (rmw's rules, sandbox/ros2_names.py)."""

from __future__ import annotations

from sandbox.ros2_names import Ros2NameError
from sandbox.ros2_names import validate_namespace as _validate

from .exceptions import InvalidNamespaceException


def validate_namespace(namespace: str) -> bool:
    try:
        _validate(namespace)
    except Ros2NameError as error:
        raise InvalidNamespaceException(error.name, error.reason, error.index) from None
    return True
