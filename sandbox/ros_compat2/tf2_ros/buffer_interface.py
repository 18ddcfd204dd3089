"""tf2_ros.buffer_interface: the transform registries shared with ROS 1 (sandbox/tf2)."""

from sandbox.tf2.buffer_interface import (
    BufferInterface,
    ConvertRegistration,
    NotImplementedException,
    TransformRegistration,
    TypeException,
    convert,
)

__all__ = [
    "BufferInterface",
    "ConvertRegistration",
    "NotImplementedException",
    "TransformRegistration",
    "TypeException",
    "convert",
]
