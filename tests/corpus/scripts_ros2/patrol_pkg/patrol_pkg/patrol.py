# Course pattern: a node of an ament_python package, started through its console_scripts entry
# (no `if __name__ == "__main__"` here): out along the corridor on odometry, turn, and back.
import math

import rclpy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.node import Node


def yaw_from(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class Patrol(Node):
    def __init__(self):
        super().__init__("patrol")
        self.declare_parameter("leg_length", 0.5)
        self.declare_parameter("speed", 0.1)
        self.declare_parameter("turn_speed", 0.6)
        self.leg = self.get_parameter("leg_length").value
        self.speed = self.get_parameter("speed").value
        self.turn_speed = self.get_parameter("turn_speed").value
        self.get_logger().info(
            f"patrol: legs of {self.leg:.2f} m at {self.speed:.2f} m/s, "
            f"use_sim_time={self.get_parameter('use_sim_time').value}"
        )
        self.pose = None
        self.state = "out"
        self.mark = None
        self.cmd_pub = self.create_publisher(Twist, "cmd_vel", 10)
        self.create_subscription(Odometry, "odom", self.on_odom, 10)
        self.create_timer(0.05, self.step)

    def on_odom(self, msg):
        p = msg.pose.pose
        self.pose = (p.position.x, p.position.y, yaw_from(p.orientation))

    def step(self):
        if self.pose is None:
            return
        x, y, yaw = self.pose
        if self.mark is None:
            self.mark = self.pose
        cmd = Twist()
        if self.state in ("out", "back"):
            if math.hypot(x - self.mark[0], y - self.mark[1]) < self.leg:
                cmd.linear.x = self.speed
            else:
                self.get_logger().info(f"leg {self.state} done at x={x:.2f} y={y:.2f}")
                self.state = "turn" if self.state == "out" else "home"
                self.mark = self.pose
        elif self.state == "turn":
            turned = abs(math.atan2(math.sin(yaw - self.mark[2]), math.cos(yaw - self.mark[2])))
            if turned < math.pi - 0.05:
                cmd.angular.z = self.turn_speed
            else:
                self.get_logger().info("turned around")
                self.state = "back"
                self.mark = self.pose
        self.cmd_pub.publish(cmd)


def main(args=None):
    rclpy.init(args=args)
    patrol = Patrol()
    rclpy.spin(patrol)
    patrol.destroy_node()
    rclpy.shutdown()
