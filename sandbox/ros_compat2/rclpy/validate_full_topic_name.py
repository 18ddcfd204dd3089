"""rclpy.validate_full_topic_name."""

from .validate_topic_name import validate_full_topic_name

__all__ = ["validate_full_topic_name"]
