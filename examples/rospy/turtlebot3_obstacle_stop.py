"""TurtleBot3 Burger, rospy as in a ROS 1 course: drive ahead, stop before an obstacle.

Subscribes `scan` (sensor_msgs/LaserScan, index 0 straight ahead, 0.0 = no return) and
publishes `cmd_vel` (geometry_msgs/Twist) at 10 Hz: the firmware stops the wheels 0.5 s after
the last command, so a controller keeps publishing.
"""

import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan

STOP_M = 0.35  # [m] stop when something is this close ahead
SPEED_M_S = 0.15  # [m/s]
ahead_m = float("inf")


def on_scan(scan):
    global ahead_m
    front = list(scan.ranges[:16]) + list(scan.ranges[-15:])  # +-15 degrees around index 0
    valid = [r for r in front if scan.range_min <= r <= scan.range_max]
    ahead_m = min(valid) if valid else float("inf")


rospy.init_node("obstacle_stop")
rospy.Subscriber("scan", LaserScan, on_scan)
pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    cmd = Twist()
    if ahead_m > STOP_M:
        cmd.linear.x = SPEED_M_S
    pub.publish(cmd)
    rate.sleep()
