#!/usr/bin/env python3
# Course pattern: the turtlesim lessons - a package RoboDojo's robots do not have.
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from turtlesim.msg import Pose


class Chaser(Node):
    def __init__(self):
        super().__init__("turtle_chaser")
        self.create_subscription(Pose, "turtle1/pose", self.on_pose, 10)
        self.pub = self.create_publisher(Twist, "turtle1/cmd_vel", 10)

    def on_pose(self, msg):
        cmd = Twist()
        cmd.angular.z = 1.0 if msg.theta < 1.0 else 0.0
        self.pub.publish(cmd)


def main():
    rclpy.init()
    rclpy.spin(Chaser())


if __name__ == "__main__":
    main()
