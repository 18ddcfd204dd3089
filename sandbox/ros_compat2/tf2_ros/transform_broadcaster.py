"""tf2_ros.TransformBroadcaster and StaticTransformBroadcaster for ROS 2, as ros2/geometry2's
tf2_ros_py: the first publishes TFMessages on "/tf" (depth 100); the static one on
"/tf_static" (depth 1, transient local) and republishes every static transform it was ever
given (the first one per child frame), so its one latched message holds them all."""

from __future__ import annotations

from typing import Any

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile

from sandbox.msgs import get_message_class

TF_DEPTH = 100  # [messages] tf2_ros's default depth for /tf
_TRANSFORM_TYPE = "geometry_msgs/msg/TransformStamped"


def _as_list(transform: Any, who: str) -> list[Any]:
    if isinstance(transform, list):
        transforms = transform
    elif hasattr(transform, "__iter__"):
        transforms = list(transform)
    else:
        transforms = [transform]
    for item in transforms:
        if getattr(item, "_type", None) != _TRANSFORM_TYPE:
            raise TypeError(
                f"{who}.sendTransform() takes a geometry_msgs.msg.TransformStamped or a list of "
                f"them, got {item!r}"
            )
    return transforms


def _check_node(node: Any, who: str) -> None:
    if not hasattr(node, "create_publisher"):
        raise TypeError(
            f"{who}(node) takes your rclpy Node (inside a Node subclass: {who}(self)); got {node!r}"
        )


class TransformBroadcaster:
    """Publishes transforms on "/tf": TransformBroadcaster(node)."""

    def __init__(self, node: Any, qos: Any = None) -> None:
        _check_node(node, "TransformBroadcaster")
        self._message_class = get_message_class("tf2_msgs/msg/TFMessage")
        self.pub_tf = node.create_publisher(
            self._message_class, "/tf", QoSProfile(depth=TF_DEPTH) if qos is None else qos
        )

    def sendTransform(self, transform: Any) -> None:
        """Publish one TransformStamped, or a list of them in one TFMessage."""
        transforms = _as_list(transform, "TransformBroadcaster")
        self.pub_tf.publish(self._message_class(transforms=transforms))


class StaticTransformBroadcaster:
    """Publishes transforms that never change on "/tf_static" (transient local)."""

    def __init__(self, node: Any, qos: Any = None) -> None:
        _check_node(node, "StaticTransformBroadcaster")
        if qos is None:
            qos = QoSProfile(
                depth=1,
                durability=DurabilityPolicy.TRANSIENT_LOCAL,
                history=HistoryPolicy.KEEP_LAST,
            )
        message_class = get_message_class("tf2_msgs/msg/TFMessage")
        self.pub_tf = node.create_publisher(message_class, "/tf_static", qos)
        self.net_message = message_class()
        self._child_frame_ids: set[str] = set()

    def sendTransform(self, transform: Any) -> None:
        """Add transforms (the first per child frame counts) and publish them all."""
        for item in _as_list(transform, "StaticTransformBroadcaster"):
            if item.child_frame_id not in self._child_frame_ids:
                self._child_frame_ids.add(item.child_frame_id)
                self.net_message.transforms.append(item)
        self.pub_tf.publish(self.net_message)
