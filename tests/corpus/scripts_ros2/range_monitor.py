#!/usr/bin/env python3
# Course pattern: a monitor started in a namespace by the launch file; its relative topic
# `too_close` lands in that namespace.
import rclpy
from rclpy.node import Node
from std_msgs.msg import Bool, Int32


class RangeMonitor(Node):
    def __init__(self):
        super().__init__("range_monitor")
        self.declare_parameter("threshold_cm", 30)
        self.threshold = self.get_parameter("threshold_cm").value
        self.pub = self.create_publisher(Bool, "too_close", 10)
        self.create_subscription(Int32, "range", self.on_range, 10)
        self.get_logger().info(
            f"namespace {self.get_namespace()}, publishing {self.pub.topic_name}, "
            f"threshold {self.threshold} cm"
        )

    def on_range(self, msg):
        self.pub.publish(Bool(data=0 < msg.data < self.threshold))


def main():
    rclpy.init()
    rclpy.spin(RangeMonitor())


if __name__ == "__main__":
    main()
