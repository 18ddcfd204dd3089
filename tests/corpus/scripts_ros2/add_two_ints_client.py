#!/usr/bin/env python3
# Course pattern: the ROS 2 tutorial async client (wait_for_service, call_async,
# spin_until_future_complete), numbers from the command line as `ros2 run pkg client 41 1`.
import sys

import rclpy
from example_interfaces.srv import AddTwoInts
from rclpy.node import Node


class AdderClient(Node):
    def __init__(self):
        super().__init__("adder_client")
        self.cli = self.create_client(AddTwoInts, "add_two_ints")
        while not self.cli.wait_for_service(timeout_sec=1.0):
            self.get_logger().info("service not available, waiting again...")
        self.req = AddTwoInts.Request()

    def send_request(self, a, b):
        self.req.a = a
        self.req.b = b
        self.future = self.cli.call_async(self.req)
        rclpy.spin_until_future_complete(self, self.future)
        return self.future.result()


def main():
    rclpy.init()
    client = AdderClient()
    response = client.send_request(int(sys.argv[1]), int(sys.argv[2]))
    client.get_logger().info(
        "Result of add_two_ints: for %d + %d = %d"  # noqa: UP031
        % (int(sys.argv[1]), int(sys.argv[2]), response.sum)
    )
    second = client.send_request(response.sum, -2)
    client.get_logger().info("and again: %d" % second.sum)  # noqa: UP031
    client.destroy_node()
    rclpy.shutdown()


if __name__ == "__main__":
    main()
