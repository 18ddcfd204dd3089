#!/usr/bin/env python3
# Course pattern: rclpy.spin in a background thread so the main loop can use node.create_rate()
# - an open-loop L: ahead 2 s, a quarter turn in 2 s, ahead 2 s, on the node's clock.
import math
import threading

import rclpy
from geometry_msgs.msg import Twist


def main():
    rclpy.init()
    node = rclpy.create_node("open_loop_l")
    pub = node.create_publisher(Twist, "cmd_vel", 10)
    spinner = threading.Thread(target=rclpy.spin, args=(node,), daemon=True)
    spinner.start()

    rate = node.create_rate(10)
    plan = [(0.15, 0.0), (0.0, math.pi / 4), (0.15, 0.0)]  # (m/s, rad/s), 2 s each
    for step, (linear, angular) in enumerate(plan):
        node.get_logger().info(f"step {step}: v={linear:.2f} w={angular:.2f}")
        cmd = Twist()
        cmd.linear.x = linear
        cmd.angular.z = angular
        start = node.get_clock().now()
        while rclpy.ok() and (node.get_clock().now() - start).nanoseconds < 2e9:
            pub.publish(cmd)
            rate.sleep()
    pub.publish(Twist())
    node.get_logger().info("L done")
    rclpy.shutdown()
    spinner.join()


if __name__ == "__main__":
    main()
