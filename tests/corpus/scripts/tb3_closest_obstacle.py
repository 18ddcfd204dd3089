#!/usr/bin/env python3
# Course pattern: turn to face the closest obstacle (argmin over the 360-beam scan).
import math

import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan

bearing = None


def scan_callback(scan):
    global bearing
    valid = [(r, i) for i, r in enumerate(scan.ranges) if scan.range_min < r < scan.range_max]
    if not valid:
        return
    closest, index = min(valid)  # noqa: RUF059
    angle = scan.angle_min + index * scan.angle_increment
    bearing = math.atan2(math.sin(angle), math.cos(angle))


rospy.init_node("face_closest")
pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)
rospy.Subscriber("scan", LaserScan, scan_callback)
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    cmd = Twist()
    if bearing is not None and abs(bearing) > math.radians(3):
        cmd.angular.z = max(-1.0, min(1.0, 1.5 * bearing))
    pub.publish(cmd)
    rate.sleep()
