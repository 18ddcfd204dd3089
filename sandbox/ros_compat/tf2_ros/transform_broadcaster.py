"""tf2_ros.TransformBroadcaster and StaticTransformBroadcaster: publish TransformStamped
messages on "tf" (queue of 100) and on "tf_static" (latched), as ros/geometry2's
transform_broadcaster.py and static_transform_broadcaster.py do. A static broadcaster's latched
message is its last sendTransform() call: send every static transform in one list."""

from __future__ import annotations

from typing import Any

import rospy

from sandbox.msgs import get_message_class

from .transform_listener import TF_STATIC_TOPIC, TF_TOPIC


def _as_list(transform: Any, extra: tuple[Any, ...], who: str) -> list[Any]:
    if extra:
        raise TypeError(
            f"{who}.sendTransform() takes a geometry_msgs/TransformStamped or a list of them; "
            "the form sendTransform(translation, rotation, time, child, parent) is "
            "tf.TransformBroadcaster's"
        )
    transforms = transform if isinstance(transform, list) else [transform]
    for item in transforms:
        if getattr(item, "_type", None) != "geometry_msgs/TransformStamped":
            raise TypeError(
                f"{who}.sendTransform() takes geometry_msgs/TransformStamped messages, got {item!r}"
            )
    return transforms


class TransformBroadcaster:
    """Publishes transforms on "tf"."""

    def __init__(self) -> None:
        self.pub_tf = rospy.Publisher(
            TF_TOPIC, get_message_class("tf2_msgs/TFMessage"), queue_size=100
        )

    def sendTransform(self, transform: Any, *extra: Any) -> None:
        """Publish one TransformStamped, or a list of them in one TFMessage."""
        transforms = _as_list(transform, extra, "tf2_ros.TransformBroadcaster")
        self.pub_tf.publish(self.pub_tf.data_class(transforms=transforms))


class StaticTransformBroadcaster:
    """Publishes transforms that never change on "tf_static" (latched)."""

    def __init__(self) -> None:
        self.pub_tf = rospy.Publisher(
            TF_STATIC_TOPIC, get_message_class("tf2_msgs/TFMessage"), queue_size=100, latch=True
        )

    def sendTransform(self, transform: Any, *extra: Any) -> None:
        """Publish (and latch) one TransformStamped, or a list of them."""
        transforms = _as_list(transform, extra, "tf2_ros.StaticTransformBroadcaster")
        self.pub_tf.publish(self.pub_tf.data_class(transforms=transforms))
