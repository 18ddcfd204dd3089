#!/usr/bin/env python3
# Course pattern: subscribers that join a second late - TRANSIENT_LOCAL gets the latched
# message, the default VOLATILE durability does not.
import rclpy
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile
from std_msgs.msg import String


class LateSubscriber(Node):
    def __init__(self):
        super().__init__("late_subscriber")
        self.join_timer = self.create_timer(1.0, self.join)

    def join(self):
        self.join_timer.cancel()
        self.get_logger().info("joining now")
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.create_subscription(String, "mission", self.on_latched, latched)
        self.create_subscription(String, "mission", self.on_volatile, 10)

    def on_latched(self, msg):
        self.get_logger().info(f"transient local got: {msg.data}")

    def on_volatile(self, msg):
        self.get_logger().info(f"volatile got: {msg.data}")


def main():
    rclpy.init()
    rclpy.spin(LateSubscriber())


if __name__ == "__main__":
    main()
