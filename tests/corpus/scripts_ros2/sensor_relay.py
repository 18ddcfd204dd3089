#!/usr/bin/env python3
# Course pattern: a driver-style node republishing a sensor with qos_profile_sensor_data
# (BEST_EFFORT, as camera and lidar drivers publish).
import rclpy
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from std_msgs.msg import Float32, Int32


class SensorRelay(Node):
    def __init__(self):
        super().__init__("sensor_relay")
        self.pub = self.create_publisher(Float32, "range_m", qos_profile_sensor_data)
        self.create_subscription(Int32, "Distance", self.relay, qos_profile_sensor_data)

    def relay(self, msg):
        self.pub.publish(Float32(data=msg.data / 100.0))


def main():
    rclpy.init()
    rclpy.spin(SensorRelay())


if __name__ == "__main__":
    main()
