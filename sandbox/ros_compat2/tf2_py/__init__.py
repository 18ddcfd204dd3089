"""`tf2_py` for ROS 2 student code (`import tf2_py as tf2`): tf2's BufferCore and exceptions,
the same objects tf2_ros re-exports (sandbox/tf2 in the ROS 2 dialect)."""

from tf2_ros.buffer import BufferCore

from sandbox.tf2.exceptions import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)

__all__ = [
    "BufferCore",
    "ConnectivityException",
    "ExtrapolationException",
    "InvalidArgumentException",
    "LookupException",
    "TimeoutException",
    "TransformException",
]
