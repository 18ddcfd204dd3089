#!/usr/bin/env python3
# Course pattern: an open-loop square driven with `while rospy.Time.now() < end:` loops.
import math

import rospy
from geometry_msgs.msg import Twist

SIDE_TIME = 1.0  # seconds per side
TURN_TIME = 1.0  # seconds per 90 degree turn

rospy.init_node("square_driver")
pub = rospy.Publisher("cmd_vel", Twist, queue_size=10)


def move(linear, angular, seconds):
    cmd = Twist()
    cmd.linear.x = linear
    cmd.angular.z = angular
    end = rospy.Time.now() + rospy.Duration(seconds)
    while rospy.Time.now() < end:
        pub.publish(cmd)


for side in range(4):
    rospy.loginfo("side %d", side + 1)
    move(0.3, 0.0, SIDE_TIME)
    move(0.0, (math.pi / 2) / TURN_TIME, TURN_TIME)
pub.publish(Twist())
rospy.loginfo("square done")
