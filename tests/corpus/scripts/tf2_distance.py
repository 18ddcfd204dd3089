#!/usr/bin/env python3
# Course pattern: tf2_ros Buffer + TransformListener, lookup_transform odom -> base_footprint.
import math

import rospy
import tf2_ros
from geometry_msgs.msg import Twist

rospy.init_node("tf2_distance")
tf_buffer = tf2_ros.Buffer()
listener = tf2_ros.TransformListener(tf_buffer)
pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)

start = None
rate = rospy.Rate(10.0)
while not rospy.is_shutdown():
    try:
        trans = tf_buffer.lookup_transform("odom", "base_footprint", rospy.Time())
    except (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException):
        rate.sleep()
        continue
    x = trans.transform.translation.x
    y = trans.transform.translation.y
    if start is None:
        start = (x, y)
    travelled = math.hypot(x - start[0], y - start[1])
    cmd = Twist()
    if travelled < 0.3:
        cmd.linear.x = 0.1
        pub.publish(cmd)
    else:
        pub.publish(cmd)
        rospy.loginfo("travelled %.2f m", travelled)
        break
    rate.sleep()
