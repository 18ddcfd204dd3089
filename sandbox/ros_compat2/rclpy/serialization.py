"""rclpy.serialization: CDR bytes of a message, as rclpy.serialization does it."""

from __future__ import annotations

from typing import Any


def serialize_message(message: Any) -> bytes:
    if not hasattr(message, "serialize"):
        raise TypeError(f"serialize_message() takes a ROS message, got {type(message).__name__}")
    return message.serialize()


def deserialize_message(serialized_message: bytes, message_type: Any) -> Any:
    return message_type.deserialize(serialized_message)
