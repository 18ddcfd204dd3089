#!/usr/bin/env python3
# Course pattern: the ROS 2 tutorial subscriber (a Node subclass, create_subscription, depth 10).
import rclpy
from rclpy.node import Node
from std_msgs.msg import String


class Listener(Node):
    def __init__(self):
        super().__init__("listener")
        self.subscription = self.create_subscription(String, "chatter", self.listener_callback, 10)
        self.subscription  # noqa: B018 - prevent unused variable warning

    def listener_callback(self, msg):
        self.get_logger().info('I heard: "%s"' % msg.data)  # noqa: UP031


def main(args=None):
    rclpy.init(args=args)
    listener = Listener()
    rclpy.spin(listener)
    listener.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
