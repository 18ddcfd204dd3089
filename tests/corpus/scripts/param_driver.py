#!/usr/bin/env python3
# Course pattern: private, global and relative parameters with defaults, rosrun-style argv.
import sys

import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32

rospy.init_node("param_driver")
speed = rospy.get_param("~speed", 0.05)
stop_distance = rospy.get_param("~stop_distance", 0.25)
robot_name = rospy.get_param("/robot_name", "unnamed robot")
rate_hz = rospy.get_param("rate", 10)
args = rospy.myargv(argv=sys.argv)
rospy.loginfo("%s: speed %.2f m/s, stop at %.2f m", robot_name, speed, stop_distance)
rospy.loginfo("extra arguments: %s", args[1:])

distance = None


def on_distance(msg):
    global distance
    if msg.data > 0:
        distance = msg.data / 100.0


rospy.Subscriber("Distance", Int32, on_distance)
pub = rospy.Publisher("Control", Twist, queue_size=1)
rate = rospy.Rate(rate_hz)
while not rospy.is_shutdown():
    cmd = Twist()
    if distance is not None and distance > stop_distance:
        cmd.linear.x = speed
    pub.publish(cmd)
    rate.sleep()
