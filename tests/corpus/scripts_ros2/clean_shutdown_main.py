#!/usr/bin/env python3
# Course pattern: the Jazzy-era main - spin inside try/except (KeyboardInterrupt,
# ExternalShutdownException), destroy_node and try_shutdown in finally.
import rclpy
from geometry_msgs.msg import Twist
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node


class SlowCruise(Node):
    def __init__(self):
        super().__init__("slow_cruise")
        self.pub = self.create_publisher(Twist, "Control", 10)
        self.ticks = 0
        self.create_timer(0.1, self.on_timer)

    def on_timer(self):
        self.ticks += 1
        cmd = Twist()
        cmd.linear.x = 0.08
        self.pub.publish(cmd)


def main(args=None):
    rclpy.init(args=args)
    node = SlowCruise()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        node.get_logger().info(f"interrupted after {node.ticks} ticks")
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
