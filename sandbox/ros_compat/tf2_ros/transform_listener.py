"""tf2_ros.TransformListener: fills a Buffer from the run's "tf" and "tf_static" topics.

As in ros/geometry2 (tf2_ros/src/tf2_ros/transform_listener.py): it subscribes with rospy,
adds every transform of every tf2_msgs/TFMessage to the buffer (tf_static ones as static), and
clears the buffer when time jumps backwards. Callbacks run inside the node's sleeps, so the
buffer fills while the script sleeps (rate.sleep(), rospy.sleep(), spin(), or a lookup's
timeout). Keep a reference to the listener (`self.listener = ...`), as ROS examples do.
"""

from __future__ import annotations

from typing import Any

import rospy

from sandbox.msgs import get_message_class

TF_TOPIC = "/tf"
TF_STATIC_TOPIC = "/tf_static"


class TransformListener:
    """Subscribes to tf and tf_static and feeds `buffer` (a tf2_ros.Buffer)."""

    def __init__(
        self,
        buffer: Any,
        queue_size: int | None = None,
        buff_size: int = 65536,
        tcp_nodelay: bool = False,
    ) -> None:
        if not (hasattr(buffer, "set_transform") and hasattr(buffer, "set_transform_static")):
            raise TypeError(
                "TransformListener() takes the buffer to fill: "
                "buffer = tf2_ros.Buffer(); listener = tf2_ros.TransformListener(buffer)"
            )
        self.buffer = buffer
        self.last_update = rospy.Time.now()
        message_class = get_message_class("tf2_msgs/TFMessage")
        self.tf_sub = rospy.Subscriber(
            TF_TOPIC, message_class, self.callback, queue_size=queue_size, buff_size=buff_size
        )
        self.tf_static_sub = rospy.Subscriber(
            TF_STATIC_TOPIC,
            message_class,
            self.static_callback,
            queue_size=queue_size,
            buff_size=buff_size,
        )

    def unregister(self) -> None:
        """Stop listening (the buffer keeps what it has)."""
        self.tf_sub.unregister()
        self.tf_static_sub.unregister()

    def check_for_reset(self) -> None:
        now = rospy.Time.now()
        if now < self.last_update:
            rospy.logwarn(
                f"Detected jump back in time of {(self.last_update - now).to_sec():f}s. "
                "Clearing TF buffer."
            )
            self.buffer.clear()
        self.last_update = now

    @staticmethod
    def _authority(data: Any) -> str:
        header = getattr(data, "_connection_header", None) or {}
        return header.get("callerid", "default_authority")

    def callback(self, data: Any) -> None:
        self.check_for_reset()
        who = self._authority(data)
        for transform in data.transforms:
            self.buffer.set_transform(transform, who)

    def static_callback(self, data: Any) -> None:
        self.check_for_reset()
        who = self._authority(data)
        for transform in data.transforms:
            self.buffer.set_transform_static(transform, who)
