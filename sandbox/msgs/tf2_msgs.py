"""tf2_msgs: the transform tree message published on ``/tf`` (definition as in ros/geometry2)."""

from __future__ import annotations

from . import geometry_msgs as _geometry_msgs  # noqa: F401  # registers TransformStamped
from ._core import Message


class TFMessage(Message):
    """A batch of transforms, each the pose of a child frame in its parent frame."""

    _type = "tf2_msgs/TFMessage"
    _definition = """
geometry_msgs/TransformStamped[] transforms
"""
