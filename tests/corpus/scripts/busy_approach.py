#!/usr/bin/env python3
# Course pattern: a control loop that never sleeps (polls a global set by the callback).
import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32

distance = 100


def callback(msg):
    global distance
    distance = msg.data


rospy.init_node("busy_approach")
pub = rospy.Publisher("Control", Twist, queue_size=1)
sub = rospy.Subscriber("Distance", Int32, callback)

cmd = Twist()
while not rospy.is_shutdown():
    if distance > 25:
        cmd.linear.x = 0.1
    else:
        cmd.linear.x = 0.0
    pub.publish(cmd)
