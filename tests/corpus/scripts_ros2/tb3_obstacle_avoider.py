#!/usr/bin/env python3
# Course pattern: TurtleBot3 obstacle avoidance in ROS 2 - scan with qos_profile_sensor_data,
# a front sector of the 360 LDS-01 beams, forward or turn left, Twist on cmd_vel at 10 Hz.
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import LaserScan

SAFE_DISTANCE = 0.45  # [m]
LINEAR_SPEED = 0.15  # [m/s]
ANGULAR_SPEED = 0.8  # [rad/s]


class ObstacleAvoider(Node):
    def __init__(self):
        super().__init__("obstacle_avoider")
        self.scan_ranges = []
        self.turning = False
        self.create_subscription(LaserScan, "scan", self.scan_callback, qos_profile_sensor_data)
        self.cmd_vel_pub = self.create_publisher(Twist, "cmd_vel", 10)
        self.create_timer(0.1, self.update)

    def scan_callback(self, msg):
        self.scan_ranges = [
            r if msg.range_min < r < msg.range_max else msg.range_max for r in msg.ranges
        ]

    def update(self):
        if not self.scan_ranges:
            return
        front = min(self.scan_ranges[:20] + self.scan_ranges[-20:])
        twist = Twist()
        if front < SAFE_DISTANCE:
            if not self.turning:
                self.get_logger().info(f"obstacle at {front:.2f} m, turning")
            self.turning = True
            twist.angular.z = ANGULAR_SPEED
        else:
            if self.turning:
                self.get_logger().info("path clear, driving")
            self.turning = False
            twist.linear.x = LINEAR_SPEED
        self.cmd_vel_pub.publish(twist)


def main(args=None):
    rclpy.init(args=args)
    node = ObstacleAvoider()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
