"""`tf2_ros` for student code: Buffer, TransformListener, TransformBroadcaster,
StaticTransformBroadcaster and tf2's exceptions, with the behaviour of ROS 1 noetic's tf2_ros
(ros/geometry2). The frames come from the run's "tf" topic (and "tf_static"):

    buffer = tf2_ros.Buffer()
    listener = tf2_ros.TransformListener(buffer)
    t = buffer.lookup_transform("map", "base_link", rospy.Time(0), rospy.Duration(1.0))

Transforming messages (buffer.transform(pose_stamped, "map")) needs `import tf2_geometry_msgs`,
as in ROS. BufferClient/BufferServer (the tf2 action interface) are not provided.
"""

from typing import Any

from .buffer import Buffer
from .buffer_core import BufferCore
from .buffer_interface import (
    BufferInterface,
    ConvertRegistration,
    NotImplementedException,
    Stamped,
    TransformRegistration,
    TypeException,
    convert,
)
from .exceptions import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)
from .transform_broadcaster import StaticTransformBroadcaster, TransformBroadcaster
from .transform_listener import TransformListener

__all__ = [
    "Buffer",
    "BufferCore",
    "BufferInterface",
    "ConnectivityException",
    "ConvertRegistration",
    "ExtrapolationException",
    "InvalidArgumentException",
    "LookupException",
    "NotImplementedException",
    "Stamped",
    "StaticTransformBroadcaster",
    "TimeoutException",
    "TransformBroadcaster",
    "TransformException",
    "TransformListener",
    "TransformRegistration",
    "TypeException",
    "convert",
]

_NOT_PROVIDED = {
    "BufferClient": "the tf2 action server is not part of a RoboDojo run; use tf2_ros.Buffer() "
    "with a tf2_ros.TransformListener(buffer)",
    "BufferServer": "the tf2 action server is not part of a RoboDojo run; every node can keep "
    "its own tf2_ros.Buffer() with a tf2_ros.TransformListener(buffer)",
    "MessageFilter": "tf2_ros.MessageFilter is C++ only in ROS 1; in Python, call "
    "buffer.can_transform(...) in your callback",
}


def __getattr__(name: str) -> Any:
    if name in _NOT_PROVIDED:
        raise AttributeError(f"tf2_ros.{name} is not available in RoboDojo: {_NOT_PROVIDED[name]}")
    raise AttributeError(
        f"module 'tf2_ros' has no attribute '{name}'; RoboDojo's tf2_ros provides "
        + ", ".join(__all__)
    )
