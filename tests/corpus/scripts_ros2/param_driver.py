#!/usr/bin/env python3
# Course pattern: parameters declared with defaults and read once (overridable with
# `--ros-args -p speed:=0.1`, a launch file or a YAML file).
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from std_msgs.msg import Int32


class ParamDriver(Node):
    def __init__(self):
        super().__init__("param_driver")
        self.declare_parameter("speed", 0.05)
        self.declare_parameter("stop_distance", 0.25)
        self.declare_parameter("robot_name", "unnamed robot")
        self.speed = self.get_parameter("speed").get_parameter_value().double_value
        self.stop_distance = self.get_parameter("stop_distance").value
        name = self.get_parameter("robot_name").get_parameter_value().string_value
        self.get_logger().info(
            f"{name}: speed {self.speed:.2f} m/s, stop at {self.stop_distance:.2f} m"
        )
        self.distance = None
        self.create_subscription(Int32, "Distance", self.on_distance, 10)
        self.pub = self.create_publisher(Twist, "Control", 10)
        self.timer = self.create_timer(0.1, self.on_timer)

    def on_distance(self, msg):
        if msg.data > 0:
            self.distance = msg.data / 100.0

    def on_timer(self):
        cmd = Twist()
        if self.distance is not None and self.distance > self.stop_distance:
            cmd.linear.x = self.speed
        self.pub.publish(cmd)


def main(args=None):
    rclpy.init(args=args)
    node = ParamDriver()
    rclpy.spin(node)
    node.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
