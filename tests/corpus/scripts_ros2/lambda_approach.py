#!/usr/bin/env python3
# Course pattern: a subscriber whose callback is a lambda, and a timer that drives on the value.
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from std_msgs.msg import Int32

STOP_AT_M = 0.35  # [m]


class LambdaApproach(Node):
    def __init__(self):
        super().__init__("lambda_approach")
        self.distance_m = None
        self.create_subscription(
            Int32, "Distance", lambda msg: setattr(self, "distance_m", msg.data / 100.0), 10
        )
        self.cmd_pub = self.create_publisher(Twist, "Control", 10)
        self.create_timer(0.05, self.control_loop)

    def control_loop(self):
        if self.distance_m is None:
            return
        cmd = Twist()
        error = self.distance_m - STOP_AT_M
        cmd.linear.x = max(-0.1, min(0.1, 0.8 * error))
        self.cmd_pub.publish(cmd)


def main():
    rclpy.init()
    node = LambdaApproach()
    rclpy.spin(node)


if __name__ == "__main__":
    main()
