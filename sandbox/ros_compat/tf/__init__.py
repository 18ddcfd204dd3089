"""`tf` (the ROS 1 classic transform library) for student code, as ROS 1 noetic ships it: a
layer over tf2_ros (ros/geometry, tf/src/tf). TransformListener.lookupTransform returns
([x, y, z], [x, y, z, w]); tf.transformations holds the matrix and quaternion helpers; the
exceptions are tf2's, so `except (tf.LookupException, tf.ConnectivityException,
tf.ExtrapolationException):` works as in ROS.
"""

from typing import Any

from tf2_ros import ConnectivityException, ExtrapolationException, LookupException
from tf2_ros import TransformException as Exception

from . import transformations
from .broadcaster import TransformBroadcaster
from .listener import Transformer, TransformerROS, TransformListener

__all__ = [
    "ConnectivityException",
    "Exception",
    "ExtrapolationException",
    "LookupException",
    "TransformBroadcaster",
    "TransformListener",
    "Transformer",
    "TransformerROS",
    "transformations",
]

_NOT_PROVIDED = {
    "MessageFilter": "tf.MessageFilter is C++ only; call listener.canTransform(...) in your "
    "callback instead",
    "TransformListenerThread": "it is not part of ROS 1 noetic's tf either; use "
    "tf.TransformListener()",
}


def __getattr__(name: str) -> Any:
    if name in _NOT_PROVIDED:
        raise AttributeError(f"tf.{name} is not available in RoboDojo: {_NOT_PROVIDED[name]}")
    raise AttributeError(
        f"module 'tf' has no attribute '{name}'; RoboDojo's tf provides " + ", ".join(__all__)
    )
