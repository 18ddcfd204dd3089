"""tf2_ros.TransformListener for ROS 2: fills a Buffer from "/tf" and "/tf_static".

As ros2/geometry2's tf2_ros_py/tf2_ros/transform_listener.py: two subscriptions on the node
(depth 100; /tf_static transient-local, so a late listener still gets every static frame), each
message's transforms added to the buffer with authority "default_authority". The callbacks run
when the node spins (rclpy.spin, spin_once, an executor), like every other callback.
spin_thread=True (a thread spinning the node in rclpy) is refused with a sentence: a node here
has one thread, and spinning it in the main loop fills the buffer the same way.
"""

from __future__ import annotations

from typing import Any

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile

from sandbox.msgs import get_message_class

DEFAULT_TF_TOPIC = "/tf"
DEFAULT_STATIC_TF_TOPIC = "/tf_static"
LISTENER_DEPTH = 100  # [messages] tf2_ros's default history depth for both subscriptions


class TransformListener:
    """Subscribes to /tf and /tf_static on `node` and feeds `buffer` (a tf2_ros.Buffer)."""

    def __init__(
        self,
        buffer: Any,
        node: Any,
        *,
        spin_thread: bool = False,
        qos: Any = None,
        static_qos: Any = None,
        tf_topic: str = DEFAULT_TF_TOPIC,
        tf_static_topic: str = DEFAULT_STATIC_TF_TOPIC,
    ) -> None:
        if not (hasattr(buffer, "set_transform") and hasattr(buffer, "set_transform_static")):
            raise TypeError(
                "TransformListener(buffer, node) takes the buffer to fill first: "
                "self.tf_buffer = Buffer(); self.tf_listener = TransformListener(self.tf_buffer, "
                "self)"
            )
        if not hasattr(node, "create_subscription"):
            raise TypeError(
                "TransformListener(buffer, node) takes your rclpy Node second (inside a Node "
                f"subclass: TransformListener(self.tf_buffer, self)); got {node!r}"
            )
        if spin_thread:
            raise ValueError(
                "TransformListener(..., spin_thread=True) starts a thread that spins the node; "
                "RoboDojo runs a node on one thread. Leave spin_thread out and spin the node "
                "(rclpy.spin(node) or rclpy.spin_once(node) in your loop): the listener's "
                "callbacks fill the buffer the same way"
            )
        if qos is None:
            qos = QoSProfile(
                depth=LISTENER_DEPTH,
                durability=DurabilityPolicy.VOLATILE,
                history=HistoryPolicy.KEEP_LAST,
            )
        if static_qos is None:
            static_qos = QoSProfile(
                depth=LISTENER_DEPTH,
                durability=DurabilityPolicy.TRANSIENT_LOCAL,
                history=HistoryPolicy.KEEP_LAST,
            )
        self.buffer = buffer
        self.node = node
        message_class = get_message_class("tf2_msgs/msg/TFMessage")
        self.tf_sub = node.create_subscription(message_class, tf_topic, self.callback, qos)
        self.tf_static_sub = node.create_subscription(
            message_class, tf_static_topic, self.static_callback, static_qos
        )

    def unregister(self) -> None:
        """Stop listening (the buffer keeps what it has)."""
        self.node.destroy_subscription(self.tf_sub)
        self.node.destroy_subscription(self.tf_static_sub)

    def callback(self, data: Any) -> None:
        for transform in data.transforms:
            self.buffer.set_transform(transform, "default_authority")

    def static_callback(self, data: Any) -> None:
        for transform in data.transforms:
            self.buffer.set_transform_static(transform, "default_authority")
