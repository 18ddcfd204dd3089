#!/usr/bin/env python3
# Course pattern: a monitor node that logs every command it sees (as `rostopic echo` would).
import rospy
from geometry_msgs.msg import Twist


def callback(msg):
    rospy.loginfo("cmd linear %.2f angular %.2f", msg.linear.x, msg.angular.z)


rospy.init_node("cmd_monitor")
rospy.Subscriber("Control", Twist, callback)
rospy.spin()
