#!/usr/bin/env python3
# Course pattern: tf2_ros Buffer + TransformListener in a Node, lookup_transform of base_link in
# odom with rclpy.time.Time() (latest), TransformException caught while the tree fills.
import math

import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from rclpy.time import Time
from tf2_ros import TransformException
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener


class OdomDistance(Node):
    def __init__(self):
        super().__init__("tf2_odom_distance")
        self.tf_buffer = Buffer()
        self.tf_listener = TransformListener(self.tf_buffer, self)
        self.pub = self.create_publisher(Twist, "cmd_vel", 10)
        self.start = None
        self.done = False
        self.timer = self.create_timer(0.1, self.on_timer)

    def on_timer(self):
        try:
            t = self.tf_buffer.lookup_transform("odom", "base_link", Time())
        except TransformException as ex:
            self.get_logger().info(f"Could not transform odom to base_link: {ex}")
            return
        x = t.transform.translation.x
        y = t.transform.translation.y
        if self.start is None:
            self.start = (x, y)
        travelled = math.hypot(x - self.start[0], y - self.start[1])
        cmd = Twist()
        if travelled < 0.3:
            cmd.linear.x = 0.1
        elif not self.done:
            self.done = True
            self.get_logger().info(f"travelled {travelled:.2f} m")
        self.pub.publish(cmd)


def main():
    rclpy.init()
    node = OdomDistance()
    rclpy.spin(node)


if __name__ == "__main__":
    main()
