#!/usr/bin/env python3
# Course pattern: the old tf.TransformListener API (lookupTransform in try/except) in a loop.
import math

import rospy
import tf
from geometry_msgs.msg import Twist

rospy.init_node("tf_listener_drive")
listener = tf.TransformListener()
pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)
listener.waitForTransform("odom", "base_link", rospy.Time(0), rospy.Duration(4.0))

start = None
rate = rospy.Rate(10.0)
while not rospy.is_shutdown():
    try:
        (trans, rot) = listener.lookupTransform("odom", "base_link", rospy.Time(0))
    except (tf.LookupException, tf.ConnectivityException, tf.ExtrapolationException):
        continue
    if start is None:
        start = trans
    travelled = math.hypot(trans[0] - start[0], trans[1] - start[1])
    yaw = tf.transformations.euler_from_quaternion(rot)[2]
    cmd = Twist()
    if travelled < 0.4:
        cmd.linear.x = 0.2
    pub.publish(cmd)
    if travelled >= 0.4:
        rospy.loginfo("travelled %.2f m, yaw %.1f deg", travelled, math.degrees(yaw))
        break
    rate.sleep()
