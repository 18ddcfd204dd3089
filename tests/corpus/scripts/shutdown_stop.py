#!/usr/bin/env python3
# Course pattern: an on_shutdown hook that publishes a zero Twist so the robot stops.
import rospy
from geometry_msgs.msg import Twist

rospy.init_node("drive_then_stop")
pub = rospy.Publisher("Control", Twist, queue_size=1)


def shutdown_hook():
    rospy.loginfo("stopping the robot")
    pub.publish(Twist())


rospy.on_shutdown(shutdown_hook)

move = Twist()
move.linear.x = 0.1
rate = rospy.Rate(10)
start = rospy.get_time()
while not rospy.is_shutdown():
    if rospy.get_time() - start >= 1.5:
        rospy.signal_shutdown("time is up")
        break
    pub.publish(move)
    rate.sleep()
