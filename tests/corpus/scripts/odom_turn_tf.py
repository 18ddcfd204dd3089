#!/usr/bin/env python3
# Course pattern: yaw from odometry with tf.transformations.euler_from_quaternion, P turn.
import math

import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from tf.transformations import euler_from_quaternion

yaw = None


def odom_callback(msg):
    global yaw
    q = msg.pose.pose.orientation
    (roll, pitch, yaw) = euler_from_quaternion([q.x, q.y, q.z, q.w])  # noqa: RUF059


def angle_diff(a, b):
    return math.atan2(math.sin(a - b), math.cos(a - b))


rospy.init_node("turn_90")
pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)
rospy.Subscriber("odom", Odometry, odom_callback)
rate = rospy.Rate(20)
while yaw is None and not rospy.is_shutdown():
    rate.sleep()
target = yaw + math.pi / 2
rospy.loginfo("start yaw %.1f deg, target %.1f deg", math.degrees(yaw), math.degrees(target))
while not rospy.is_shutdown():
    error = angle_diff(target, yaw)
    if abs(error) < math.radians(1.0):
        break
    cmd = Twist()
    cmd.angular.z = max(-1.0, min(1.0, 2.0 * error))
    pub.publish(cmd)
    rate.sleep()
pub.publish(Twist())
rospy.loginfo("reached yaw %.1f deg", math.degrees(yaw))
