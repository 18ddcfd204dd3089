"""tf2_ros's BufferInterface for ROS 1: buffer.transform(stamped, target_frame) through the
registries shared with ROS 2 (sandbox/tf2/buffer_interface.py), and Stamped() with a ROS 1
std_msgs/Header."""

from typing import Any

from sandbox.msgs import get_message_class
from sandbox.tf2.buffer_interface import (
    NO_WAIT,
    BufferInterface,
    ConvertRegistration,
    NotImplementedException,
    TransformRegistration,
    TypeException,
    convert,
)

__all__ = [
    "NO_WAIT",
    "BufferInterface",
    "ConvertRegistration",
    "NotImplementedException",
    "Stamped",
    "TransformRegistration",
    "TypeException",
    "convert",
]


def Stamped(obj: Any, stamp: Any, frame_id: str) -> Any:
    """Give `obj` a std_msgs/Header with this stamp and frame."""
    obj.header = get_message_class("std_msgs/Header")(frame_id=frame_id, stamp=stamp)
    return obj
