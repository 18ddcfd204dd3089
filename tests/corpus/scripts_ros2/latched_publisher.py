#!/usr/bin/env python3
# Course pattern: a "latched" topic in ROS 2 - published once with TRANSIENT_LOCAL durability,
# the publisher node stays up so late subscribers still get it.
import rclpy
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

latched_qos = QoSProfile(
    depth=1,
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
    reliability=ReliabilityPolicy.RELIABLE,
)


class MissionPublisher(Node):
    def __init__(self):
        super().__init__("mission_publisher")
        self.pub = self.create_publisher(String, "mission", latched_qos)
        self.pub.publish(String(data="inspect the north corridor"))
        self.get_logger().info("mission published once")


def main():
    rclpy.init()
    node = MissionPublisher()
    try:  # noqa: SIM105
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass


if __name__ == "__main__":
    main()
