#!/usr/bin/env python3
# Course pattern: the ROS 2 tutorial service server (example_interfaces AddTwoInts, spin).
import rclpy
from example_interfaces.srv import AddTwoInts
from rclpy.node import Node


class AdderService(Node):
    def __init__(self):
        super().__init__("adder_service")
        self.srv = self.create_service(AddTwoInts, "add_two_ints", self.add_callback)

    def add_callback(self, request, response):
        response.sum = request.a + request.b
        self.get_logger().info("Incoming request a: %d b: %d" % (request.a, request.b))  # noqa: UP031
        return response


def main():
    rclpy.init()
    service = AdderService()
    rclpy.spin(service)
    rclpy.shutdown()


if __name__ == "__main__":
    main()
