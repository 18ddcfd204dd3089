#!/usr/bin/env python3
# Course pattern: a synchronous service call inside a timer, made safe with a
# ReentrantCallbackGroup and a MultiThreadedExecutor (the "sync deadlock" lesson).
import rclpy
from example_interfaces.srv import AddTwoInts
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node


class Accumulator(Node):
    def __init__(self):
        super().__init__("accumulator")
        group = ReentrantCallbackGroup()
        self.client = self.create_client(AddTwoInts, "add_two_ints", callback_group=group)
        self.total = 0
        self.calls = 0
        self.timer = self.create_timer(0.25, self.on_timer, callback_group=group)

    def on_timer(self):
        if not self.client.service_is_ready():
            self.get_logger().info("waiting for add_two_ints")
            return
        request = AddTwoInts.Request(a=self.total, b=3)
        response = self.client.call(request)
        self.calls += 1
        self.total = response.sum
        self.get_logger().info(f"call {self.calls}: total is {self.total}")
        if self.calls == 8:
            self.timer.cancel()
            self.get_logger().info("done: 8 calls")


def main():
    rclpy.init()
    node = Accumulator()
    executor = MultiThreadedExecutor()
    executor.add_node(node)
    try:
        executor.spin()
    finally:
        executor.shutdown()
        node.destroy_node()


if __name__ == "__main__":
    main()
