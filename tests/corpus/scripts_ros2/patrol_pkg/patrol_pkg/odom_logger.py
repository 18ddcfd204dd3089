# Course pattern: a second console_scripts node of the package - odometry logged once a second,
# its topic given by a remapping in the launch file.
import rclpy
from nav_msgs.msg import Odometry
from rclpy.node import Node


class OdomLogger(Node):
    def __init__(self):
        super().__init__("odom_logger")
        self.declare_parameter("label", "odom")
        self.label = self.get_parameter("label").value
        self.create_subscription(Odometry, "wheel_odom", self.on_odom, 10)

    def on_odom(self, msg):
        p = msg.pose.pose.position
        self.get_logger().info(f"{self.label}: x={p.x:.2f} y={p.y:.2f}", throttle_duration_sec=1.0)


def main():
    rclpy.init()
    node = OdomLogger()
    try:  # noqa: SIM105
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
