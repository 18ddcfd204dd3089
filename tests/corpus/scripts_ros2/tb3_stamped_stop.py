#!/usr/bin/env python3
# Course pattern: TurtleBot3 on ROS 2 Jazzy takes TwistStamped on cmd_vel - drive ahead until
# the front beam reads less than 0.35 m, stamped with the node's clock.
import rclpy
from geometry_msgs.msg import TwistStamped
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import LaserScan

STOP_DISTANCE = 0.35  # [m]


class StampedStop(Node):
    def __init__(self):
        super().__init__("stamped_stop")
        scan_qos = QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT)
        self.create_subscription(LaserScan, "scan", self.on_scan, scan_qos)
        self.pub = self.create_publisher(TwistStamped, "cmd_vel", 10)
        self.front = None
        self.stopped = False
        self.create_timer(0.1, self.on_timer)

    def on_scan(self, scan):
        window = [r for r in list(scan.ranges[:11]) + list(scan.ranges[-10:]) if r > scan.range_min]
        self.front = min(window) if window else scan.range_max

    def on_timer(self):
        if self.front is None:
            return
        cmd = TwistStamped()
        cmd.header.stamp = self.get_clock().now().to_msg()
        cmd.header.frame_id = "base_link"
        if self.front > STOP_DISTANCE:
            cmd.twist.linear.x = 0.15
        elif not self.stopped:
            self.stopped = True
            self.get_logger().info(f"Stop! obstacle at {self.front:.2f} m")
        self.pub.publish(cmd)


def main():
    rclpy.init()
    node = StampedStop()
    rclpy.spin(node)


if __name__ == "__main__":
    main()
