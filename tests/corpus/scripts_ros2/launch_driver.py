#!/usr/bin/env python3
# Course pattern: a node configured by a launch file - parameters from YAML (nested names like
# gains.kp), one from a launch argument, topics renamed by remappings.
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from std_msgs.msg import Int32


class LaunchDriver(Node):
    def __init__(self):
        super().__init__("launch_driver")
        self.declare_parameter("robot_name", "robot")
        self.declare_parameter("speed", 0.05)
        self.declare_parameter("stop_distance", 0.25)
        self.declare_parameter("gains.kp", 0.5)
        self.declare_parameter("gains.ki", 0.0)
        self.speed = self.get_parameter("speed").value
        self.stop_distance = self.get_parameter("stop_distance").value
        self.kp = self.get_parameter("gains.kp").value
        self.get_logger().info(
            f"{self.get_parameter('robot_name').value}: speed {self.speed:.2f}, "
            f"stop at {self.stop_distance:.2f} m, kp {self.kp:.2f}"
        )
        self.distance = None
        self.create_subscription(Int32, "range", self.on_range, 10)
        self.pub = self.create_publisher(Twist, "cmd_vel", 10)
        self.create_timer(0.1, self.on_timer)

    def on_range(self, msg):
        if msg.data > 0:
            self.distance = msg.data / 100.0

    def on_timer(self):
        cmd = Twist()
        if self.distance is not None:
            error = self.distance - self.stop_distance
            cmd.linear.x = max(-self.speed, min(self.speed, self.kp * error))
        self.pub.publish(cmd)


def main():
    rclpy.init()
    rclpy.spin(LaunchDriver())


if __name__ == "__main__":
    main()
