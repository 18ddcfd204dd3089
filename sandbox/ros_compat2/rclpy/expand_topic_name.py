"""rclpy.expand_topic_name (rcl_expand_topic_name, sandbox/ros2_names.py)."""

from __future__ import annotations

from sandbox.ros2_names import Ros2NameError
from sandbox.ros2_names import expand_topic_name as _expand

from .exceptions import InvalidTopicNameException


def expand_topic_name(topic_name: str, node_name: str, node_namespace: str) -> str:
    try:
        return _expand(topic_name, node_name, node_namespace or "/")
    except Ros2NameError as error:
        raise InvalidTopicNameException(error.name, error.reason, error.index) from None
