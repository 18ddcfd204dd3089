#!/usr/bin/env python3
# Course pattern: where am I on the map - lookup_transform("map", "base_link") with a timeout,
# yaw from the quaternion by hand, turn in place by 90 degrees.
import math

import rclpy
from geometry_msgs.msg import Twist
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.time import Time
from tf2_ros import LookupException, TransformException
from tf2_ros.buffer import Buffer
from tf2_ros.transform_listener import TransformListener


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class MapTurn(Node):
    def __init__(self):
        super().__init__("tf2_map_turn")
        self.buffer = Buffer()
        self.listener = TransformListener(self.buffer, self)
        self.cmd_pub = self.create_publisher(Twist, "cmd_vel", 1)
        self.start_yaw = None
        self.create_timer(0.05, self.step)

    def step(self):
        try:
            tf = self.buffer.lookup_transform(
                "map", "base_link", Time(), timeout=Duration(seconds=0.0)
            )
        except (LookupException, TransformException):
            return
        yaw = yaw_of(tf.transform.rotation)
        if self.start_yaw is None:
            self.start_yaw = yaw
            p = tf.transform.translation
            self.get_logger().info(f"start in map: x={p.x:.2f} y={p.y:.2f} yaw={yaw:.2f}")
        turned = math.atan2(math.sin(yaw - self.start_yaw), math.cos(yaw - self.start_yaw))
        cmd = Twist()
        if turned < math.pi / 2 - 0.03:
            cmd.angular.z = 0.4
        self.cmd_pub.publish(cmd)


def main():
    rclpy.init()
    rclpy.spin(MapTurn())


if __name__ == "__main__":
    main()
