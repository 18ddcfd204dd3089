#!/usr/bin/env python3
# Course pattern: a while loop around rclpy.spin_once (no timer): read, decide, publish.
import rclpy
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32

latest_cm = None


def on_distance(msg):
    global latest_cm
    latest_cm = msg.data


def main():
    rclpy.init()
    node = rclpy.create_node("spin_once_driver")
    node.create_subscription(Int32, "Distance", on_distance, 10)
    pub = node.create_publisher(Twist, "Control", 10)
    cmd = Twist()
    while rclpy.ok():
        rclpy.spin_once(node, timeout_sec=0.1)
        if latest_cm is None:
            continue
        if latest_cm > 30:
            cmd.linear.x = 0.08
        else:
            cmd.linear.x = 0.0
            pub.publish(cmd)
            node.get_logger().info("close enough: %d cm" % latest_cm)  # noqa: UP031
            break
        pub.publish(cmd)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
