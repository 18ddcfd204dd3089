#!/usr/bin/env python3
# Course pattern: a Rate made before init_node (real rospy refuses this too).
import rospy
from geometry_msgs.msg import Twist

pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)
rate = rospy.Rate(10)
rospy.init_node("too_early")
while not rospy.is_shutdown():
    pub.publish(Twist())
    rate.sleep()
