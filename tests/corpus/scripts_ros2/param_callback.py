#!/usr/bin/env python3
# Course pattern: add_on_set_parameters_callback validating new values (SetParametersResult),
# the node changing its own parameter while it runs.
import rclpy
from geometry_msgs.msg import Twist
from rcl_interfaces.msg import SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter


class TunableDriver(Node):
    def __init__(self):
        super().__init__("tunable_driver")
        self.declare_parameter("speed", 0.05)
        self.speed = self.get_parameter("speed").value
        self.add_on_set_parameters_callback(self.on_parameters)
        self.pub = self.create_publisher(Twist, "Control", 10)
        self.create_timer(0.1, self.drive)
        self.tuning = self.create_timer(1.0, self.tune)

    def on_parameters(self, params):
        for param in params:
            if param.name == "speed":
                if param.value < 0.0 or param.value > 0.2:
                    self.get_logger().warn(f"rejected speed {param.value}")
                    return SetParametersResult(successful=False, reason="speed must be 0..0.2 m/s")
                self.speed = param.value
                self.get_logger().info(f"speed is now {self.speed:.2f} m/s")
        return SetParametersResult(successful=True)

    def tune(self):
        self.tuning.cancel()
        results = self.set_parameters([Parameter("speed", Parameter.Type.DOUBLE, -1.0)])
        self.get_logger().info(f"setting -1.0: successful={results[0].successful}")
        results = self.set_parameters([Parameter("speed", Parameter.Type.DOUBLE, 0.1)])
        self.get_logger().info(f"setting 0.1: successful={results[0].successful}")
        self.get_logger().info(f"parameter now {self.get_parameter('speed').value}")

    def drive(self):
        cmd = Twist()
        cmd.linear.x = self.speed
        self.pub.publish(cmd)


def main():
    rclpy.init()
    rclpy.spin(TunableDriver())


if __name__ == "__main__":
    main()
