#!/usr/bin/env python3
# Course pattern: a right-wall follower (Articulated Robotics / The Construct style):
# LaserScan callback keeps the sectors, a 10 Hz timer holds 0.45 m with a P controller.
import rclpy
from geometry_msgs.msg import Twist
from rclpy.node import Node
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import LaserScan


class WallFollower(Node):
    def __init__(self):
        super().__init__("wall_follower")
        self.declare_parameter("desired_distance", 0.45)
        self.declare_parameter("forward_speed", 0.15)
        self.regions = None
        self.create_subscription(LaserScan, "/scan", self.laser_callback, qos_profile_sensor_data)
        self.cmd_pub = self.create_publisher(Twist, "/cmd_vel", 10)
        self.create_timer(0.1, self.follow_wall)

    def laser_callback(self, msg):
        def sector(start, end):
            values = [r for r in msg.ranges[start:end] if msg.range_min < r < msg.range_max]
            return min(values) if values else msg.range_max

        front = min(sector(0, 16), sector(345, 360))
        self.regions = {"front": front, "right": sector(260, 281)}

    def follow_wall(self):
        if self.regions is None:
            return
        desired = self.get_parameter("desired_distance").value
        twist = Twist()
        if self.regions["front"] < 0.4:
            twist.angular.z = 0.5
        else:
            error = desired - self.regions["right"]
            twist.linear.x = self.get_parameter("forward_speed").value
            twist.angular.z = max(-0.5, min(0.5, 1.5 * error))
        self.cmd_pub.publish(twist)


def main():
    rclpy.init()
    node = WallFollower()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()


if __name__ == "__main__":
    main()
