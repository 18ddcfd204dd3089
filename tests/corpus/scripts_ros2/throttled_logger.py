#!/usr/bin/env python3
# Course pattern: a 20 Hz sensor callback that logs at most once a second
# (get_logger().info(..., throttle_duration_sec=1)) and warns once (once=True).
import rclpy
from rclpy.node import Node
from std_msgs.msg import Int32


class DistanceMonitor(Node):
    def __init__(self):
        super().__init__("distance_monitor")
        self.count = 0
        self.create_subscription(Int32, "Distance", self.on_distance, 10)

    def on_distance(self, msg):
        self.count += 1
        self.get_logger().info(
            f"distance {msg.data} cm ({self.count} readings)", throttle_duration_sec=1
        )
        self.get_logger().warn("first reading received", once=True)


def main():
    rclpy.init()
    rclpy.spin(DistanceMonitor())


if __name__ == "__main__":
    main()
