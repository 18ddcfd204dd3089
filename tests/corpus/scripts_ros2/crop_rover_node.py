#!/usr/bin/env python3
# Course pattern: the crop-row rover's row follower as an rclpy node - lateral distance to the
# left row from the LiDAR window (0 rad at the rear, left side (0, pi)), a P law on the
# control word u (negative steers left), published as std_msgs/Float32.
import math

import rclpy
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float32

TARGET_M = 0.36  # [m] beams stop on the plants' near face, a few cm short of the row centre
GAIN = 250.0  # [1/m]


class RowFollower(Node):
    def __init__(self):
        super().__init__("row_follower")
        self.u_pub = self.create_publisher(Float32, "u", 10)
        self.create_subscription(LaserScan, "scan", self.on_scan, qos_profile_sensor_data)
        self.scans = 0

    def on_scan(self, scan):
        lateral = []
        for i, r in enumerate(scan.ranges):
            angle = scan.angle_min + i * scan.angle_increment
            if math.pi / 2 - 0.35 <= angle <= math.pi / 2 + 0.85 and r > scan.range_min:
                side = r * math.sin(angle)
                if side < 0.8:
                    lateral.append(side)
        if not lateral:
            return
        distance = sum(lateral) / len(lateral)
        u = max(-60.0, min(60.0, -GAIN * (distance - TARGET_M)))
        self.u_pub.publish(Float32(data=u))
        self.scans += 1
        if self.scans % 7 == 0:
            self.get_logger().info(f"row at {distance:.2f} m, u = {u:.1f}")


def main():
    rclpy.init()
    rclpy.spin(RowFollower())


if __name__ == "__main__":
    main()
