"""tf.TransformBroadcaster: the tf (ROS 1 classic) way to publish a transform on "tf", as in
ros/geometry's tf/src/tf/broadcaster.py (a wrapper of tf2_ros.TransformBroadcaster)."""

from __future__ import annotations

from typing import Any

import tf2_ros

from sandbox.msgs import get_message_class


class TransformBroadcaster:
    """sendTransform(translation, rotation, time, child, parent) publishes on "tf"."""

    def __init__(self, queue_size: int = 100) -> None:
        self.tf2_broadcaster = tf2_ros.TransformBroadcaster()

    def sendTransform(
        self, translation: Any, rotation: Any, time: Any, child: str, parent: str
    ) -> None:
        """Publish the pose of frame `child` in frame `parent` at `time` (a rospy.Time):
        translation (x, y, z) [m], rotation quaternion (x, y, z, w)."""
        try:
            x, y, z = (float(value) for value in translation)
            qx, qy, qz, qw = (float(value) for value in rotation)
        except (TypeError, ValueError):
            raise TypeError(
                "sendTransform(translation, rotation, time, child, parent) takes translation as "
                "(x, y, z) and rotation as a quaternion (x, y, z, w), e.g. "
                "tf.transformations.quaternion_from_euler(0, 0, yaw); got "
                f"{translation!r} and {rotation!r}"
            ) from None
        transform = get_message_class("geometry_msgs/TransformStamped")()
        transform.header.frame_id = parent
        transform.header.stamp = time
        transform.child_frame_id = child
        t, r = transform.transform.translation, transform.transform.rotation
        t.x, t.y, t.z = x, y, z
        r.x, r.y, r.z, r.w = qx, qy, qz, qw
        self.sendTransformMessage(transform)

    def sendTransformMessage(self, transform: Any) -> None:
        """Publish a geometry_msgs/TransformStamped."""
        self.tf2_broadcaster.sendTransform([transform])
