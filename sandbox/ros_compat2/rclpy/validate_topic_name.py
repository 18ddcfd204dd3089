"""rclpy.validate_topic_name and validate_full_topic_name's checks (rcl's rules, ros2_names)."""

from __future__ import annotations

from sandbox.ros2_names import Ros2NameError
from sandbox.ros2_names import validate_full_topic_name as _validate_full
from sandbox.ros2_names import validate_topic_name as _validate

from .exceptions import InvalidServiceNameException, InvalidTopicNameException

TOPIC_SEPARATOR_STRING = "/"


def _raise(error: Ros2NameError, is_service: bool) -> None:
    cls = InvalidServiceNameException if is_service else InvalidTopicNameException
    raise cls(error.name, error.reason, error.index) from None


def validate_topic_name(name: str, *, is_service: bool = False) -> bool:
    """True for a valid (not necessarily expanded) name; else InvalidTopicNameException."""
    try:
        _validate(name)
    except Ros2NameError as error:
        _raise(error, is_service)
    return True


def validate_full_topic_name(name: str, *, is_service: bool = False) -> bool:
    """True for a valid fully qualified name; else InvalidTopicNameException."""
    try:
        _validate_full(name)
    except Ros2NameError as error:
        _raise(error, is_service)
    return True
