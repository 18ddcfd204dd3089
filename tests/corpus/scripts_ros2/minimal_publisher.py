#!/usr/bin/env python3
# Course pattern: the ROS 2 tutorial publisher (a Node subclass, a 10 Hz timer, String on chatter).
import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class Talker(Node):
    def __init__(self):
        super().__init__("talker")
        self.publisher_ = self.create_publisher(String, "chatter", 10)
        self.count = 0
        self.timer = self.create_timer(0.1, self.timer_callback)

    def timer_callback(self):
        msg = String()
        msg.data = "Hello ROS 2: %d" % self.count  # noqa: UP031
        self.publisher_.publish(msg)
        self.get_logger().info('Publishing: "%s"' % msg.data)  # noqa: UP031
        self.count += 1


def main(args=None):
    rclpy.init(args=args)
    talker = Talker()
    rclpy.spin(talker)
    talker.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
