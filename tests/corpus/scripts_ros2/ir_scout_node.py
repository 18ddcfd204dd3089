#!/usr/bin/env python3
# Course pattern: the IR scout's obstacle stop as one rclpy node - point the servo ahead,
# send string motor commands, stop when the IR range (sensor_msgs/Range) gets short.
import math

import rclpy
from rclpy.node import Node
from sensor_msgs.msg import Range
from std_msgs.msg import Int16, String

STOP_RANGE = 0.25  # [m]


class IrScout(Node):
    def __init__(self):
        super().__init__("ir_scout")
        self.servo_pub = self.create_publisher(Int16, "servo_angle", 10)
        self.motor_pub = self.create_publisher(String, "motor_command", 10)
        self.create_subscription(Range, "ir_range", self.on_range, 10)
        self.range = math.inf
        self.state = "forward"
        self.create_timer(0.1, self.tick)

    def on_range(self, msg):
        self.range = msg.range

    def tick(self):
        self.servo_pub.publish(Int16(data=90))
        if self.state == "forward" and self.range < STOP_RANGE:
            self.state = "stop"
            self.get_logger().info(f"obstacle at {self.range:.2f} m: stop")
        self.motor_pub.publish(String(data=self.state))


def main():
    rclpy.init()
    rclpy.spin(IrScout())


if __name__ == "__main__":
    main()
