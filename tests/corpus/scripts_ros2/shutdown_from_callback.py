#!/usr/bin/env python3
# Course pattern: a node that ends itself - when the goal is met, the callback stops the robot
# and calls rclpy.shutdown(); spin returns and main tidies up.
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from std_msgs.msg import Int32


class DriveToWall(Node):
    def __init__(self):
        super().__init__("drive_to_wall")
        self.pub = self.create_publisher(Twist, "Control", 10)
        self.create_subscription(Int32, "Distance", self.on_distance, 10)

    def on_distance(self, msg):
        cmd = Twist()
        if msg.data > 30:
            cmd.linear.x = 0.1
            self.pub.publish(cmd)
            return
        self.pub.publish(cmd)
        self.get_logger().info(f"reached {msg.data} cm, shutting down")
        rclpy.shutdown()


def main():
    rclpy.init()
    node = DriveToWall()
    rclpy.spin(node)
    node.get_logger().info("spin returned")


if __name__ == "__main__":
    main()
