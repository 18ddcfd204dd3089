"""`tf2_ros` for ROS 2 student code, with the behaviour of ros2/geometry2's tf2_ros_py: Buffer,
TransformListener, TransformBroadcaster, StaticTransformBroadcaster and tf2's exceptions. The
frames come from the run's "/tf" (the robot's tree, published by the run) and "/tf_static":

    from tf2_ros import TransformException
    from tf2_ros.buffer import Buffer
    from tf2_ros.transform_listener import TransformListener

    self.tf_buffer = Buffer()
    self.tf_listener = TransformListener(self.tf_buffer, self)
    ...
    t = self.tf_buffer.lookup_transform("map", "base_link", rclpy.time.Time())

The tree, its time cache and the lookups are the shared core of sandbox/tf2 (the one ROS 1's
tf2_ros uses), in the ROS 2 dialect: rclpy times in, geometry_msgs/msg/TransformStamped out.
Transforming messages (buffer.transform(pose_stamped, "map")) needs `import tf2_geometry_msgs`,
as in ROS 2. BufferClient (the tf2 action interface) is not provided.
"""

from typing import Any

from sandbox.tf2.buffer_interface import (
    BufferInterface,
    ConvertRegistration,
    NotImplementedException,
    TransformRegistration,
    TypeException,
    convert,
)
from sandbox.tf2.exceptions import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)

from .buffer import Buffer, BufferCore
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


def Stamped(obj: Any, stamp: Any, frame_id: str) -> Any:
    """Give `obj` a std_msgs/msg/Header with this stamp (builtin_interfaces Time) and frame."""
    from sandbox.msgs import get_message_class

    obj.header = get_message_class("std_msgs/msg/Header")(frame_id=frame_id, stamp=stamp)
    return obj


_NOT_PROVIDED = {
    "BufferClient": "the tf2 action server is not part of a RoboDojo run; use "
    "tf2_ros.buffer.Buffer() with a TransformListener(buffer, node)",
    "MessageFilter": "tf2_ros's MessageFilter is C++ only; in Python, call "
    "buffer.can_transform(...) in your subscription callback",
    "TransformStamped": "it is a message: from geometry_msgs.msg import TransformStamped",
}


def __getattr__(name: str) -> Any:
    if name in _NOT_PROVIDED:
        raise AttributeError(f"tf2_ros.{name} is not available in RoboDojo: {_NOT_PROVIDED[name]}")
    raise AttributeError(
        f"module 'tf2_ros' has no attribute '{name}'; RoboDojo's tf2_ros provides "
        + ", ".join(__all__)
    )
