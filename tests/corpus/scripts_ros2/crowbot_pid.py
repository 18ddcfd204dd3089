#!/usr/bin/env python3
# Course pattern: the CrowBot paper's PID distance controller as an rclpy node (10 Hz timer,
# Kp=Ki=Kd=0.4, d_d=0.2 m, Distance in cm -> Control Twist), its samples saved to CSV at exit.
import csv

import rclpy
from geometry_msgs.msg import Twist
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Int32

KP, KI, KD = 0.4, 0.4, 0.4
DESIRED = 0.2  # [m]
T = 0.1  # [s] sampling period


class CrowbotPid(Node):
    def __init__(self):
        super().__init__("crowbot_pid")
        self.dr = None
        self.integral = 0.0
        self.previous_error = None
        self.samples = []
        self.create_subscription(Int32, "Distance", self.distance_cb, 10)
        self.pub = self.create_publisher(Twist, "Control", 10)
        self.create_timer(T, self.control)

    def distance_cb(self, msg):
        if msg.data > 0:
            self.dr = msg.data / 100.0

    def control(self):
        if self.dr is None:
            return
        error = self.dr - DESIRED
        self.integral += error * T
        self.integral = max(-0.05, min(0.05, self.integral))  # anti windup
        derivative = 0.0 if self.previous_error is None else (error - self.previous_error) / T
        self.previous_error = error
        u = KP * error + KI * self.integral + KD * derivative
        cmd = Twist()
        cmd.linear.x = max(-0.12, min(0.12, u))
        self.pub.publish(cmd)
        now = self.get_clock().now().nanoseconds / 1e9
        self.samples.append((now, error, cmd.linear.x))


def main():
    rclpy.init()
    node = CrowbotPid()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        with open("pid_samples.csv", "w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(["t", "error", "u"])
            writer.writerows(node.samples)
        print(f"saved {len(node.samples)} samples")
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
