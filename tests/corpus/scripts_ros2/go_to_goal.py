#!/usr/bin/env python3
# Course pattern: go-to-goal on odometry (The Construct / TurtleBot3 style): pose from
# nav_msgs/Odometry, yaw with tf_transformations.euler_from_quaternion, P control on heading.
import math

import rclpy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.node import Node
from tf_transformations import euler_from_quaternion

GOAL_X = 0.6  # [m] in odom (ahead of the start)
GOAL_Y = 0.3  # [m] in odom (to the left)


class GoToGoal(Node):
    def __init__(self):
        super().__init__("go_to_goal")
        self.x = self.y = self.yaw = None
        self.odom_sub = self.create_subscription(Odometry, "odom", self.odom_callback, 10)
        self.cmd_pub = self.create_publisher(Twist, "cmd_vel", 10)
        self.timer = self.create_timer(0.1, self.control)
        self.reached = False

    def odom_callback(self, msg):
        self.x = msg.pose.pose.position.x
        self.y = msg.pose.pose.position.y
        q = msg.pose.pose.orientation
        _, _, self.yaw = euler_from_quaternion([q.x, q.y, q.z, q.w])

    def control(self):
        if self.x is None:
            return
        cmd = Twist()
        dx, dy = GOAL_X - self.x, GOAL_Y - self.y
        distance = math.sqrt(dx**2 + dy**2)
        if distance < 0.05:
            if not self.reached:
                self.reached = True
                self.get_logger().info(f"goal reached: x={self.x:.2f} y={self.y:.2f}")
        else:
            heading_error = math.atan2(dy, dx) - self.yaw
            heading_error = math.atan2(math.sin(heading_error), math.cos(heading_error))
            cmd.angular.z = max(-1.0, min(1.0, 1.5 * heading_error))
            if abs(heading_error) < 0.3:
                cmd.linear.x = min(0.2, 0.5 * distance)
        self.cmd_pub.publish(cmd)


def main(args=None):
    rclpy.init(args=args)
    node = GoToGoal()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
