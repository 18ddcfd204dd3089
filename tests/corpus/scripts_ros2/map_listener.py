#!/usr/bin/env python3
# Course pattern: reading the map Nav2's map_server latches (TRANSIENT_LOCAL, RELIABLE, depth 1).
import rclpy
from nav_msgs.msg import OccupancyGrid
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy


class MapListener(Node):
    def __init__(self):
        super().__init__("map_listener")
        qos = QoSProfile(
            depth=1,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
            reliability=ReliabilityPolicy.RELIABLE,
        )
        self.create_subscription(OccupancyGrid, "/map", self.on_map, qos)

    def on_map(self, msg):
        info = msg.info
        occupied = sum(1 for cell in msg.data if cell > 50)
        self.get_logger().info(
            f"map {info.width}x{info.height} at {info.resolution:.3f} m/cell, "
            f"frame {msg.header.frame_id}, {occupied} occupied cells"
        )


def main():
    rclpy.init()
    rclpy.spin(MapListener())


if __name__ == "__main__":
    main()
