#!/usr/bin/env python3
# Course pattern: the QoS lesson - a RELIABLE subscriber (depth 10) to a BEST_EFFORT publisher
# hears nothing; a subscriber with a best-effort QoSProfile hears every message.
import rclpy
from rclpy.node import Node
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float32


class QosListener(Node):
    def __init__(self):
        super().__init__("qos_listener")
        self.reliable_count = 0
        self.best_effort_count = 0
        self.create_subscription(Float32, "range_m", self.on_reliable, 10)
        best_effort = QoSProfile(
            reliability=ReliabilityPolicy.BEST_EFFORT, history=HistoryPolicy.KEEP_LAST, depth=5
        )
        self.create_subscription(Float32, "range_m", self.on_best_effort, best_effort)
        self.create_timer(1.0, self.report)

    def on_reliable(self, msg):
        self.reliable_count += 1

    def on_best_effort(self, msg):
        self.best_effort_count += 1

    def report(self):
        self.get_logger().info(
            f"reliable: {self.reliable_count} messages, best effort: {self.best_effort_count}"
        )


def main():
    rclpy.init()
    rclpy.spin(QosListener())


if __name__ == "__main__":
    main()
