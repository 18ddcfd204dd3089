#!/usr/bin/env python3
# Course pattern: two nodes in one file on one executor - a sensor node converts cm to metres on
# its own topic, a controller node drives on it.
import rclpy
from geometry_msgs.msg import Twist
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float32, Int32


class RangeConverter(Node):
    def __init__(self):
        super().__init__("range_converter")
        self.pub = self.create_publisher(Float32, "range_m", 10)
        self.create_subscription(Int32, "Distance", self.convert, 10)

    def convert(self, msg):
        if msg.data > 0:
            self.pub.publish(Float32(data=msg.data / 100.0))


class Approach(Node):
    def __init__(self):
        super().__init__("approach")
        self.pub = self.create_publisher(Twist, "Control", 10)
        self.create_subscription(Float32, "range_m", self.on_range, 10)

    def on_range(self, msg):
        cmd = Twist()
        cmd.linear.x = max(-0.1, min(0.1, 0.7 * (msg.data - 0.4)))
        self.pub.publish(cmd)


def main():
    rclpy.init()
    converter = RangeConverter()
    approach = Approach()
    executor = SingleThreadedExecutor()
    executor.add_node(converter)
    executor.add_node(approach)
    try:  # noqa: SIM105
        executor.spin()
    except KeyboardInterrupt:
        pass
    converter.destroy_node()
    approach.destroy_node()
    rclpy.try_shutdown()


if __name__ == "__main__":
    main()
