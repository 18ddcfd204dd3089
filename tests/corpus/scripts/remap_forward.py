#!/usr/bin/env python3
# Course pattern: a script written for `cmd_vel`, run with a remapping (cmd_vel:=Control).
import rospy
from geometry_msgs.msg import Twist

rospy.init_node("forward")
pub = rospy.Publisher("cmd_vel", Twist, queue_size=10)
rospy.loginfo("publishing on %s", rospy.resolve_name("cmd_vel"))
move = Twist()
move.linear.x = 0.1
rate = rospy.Rate(20)
start = rospy.get_time()
while not rospy.is_shutdown() and rospy.get_time() - start < 2.0:
    pub.publish(move)
    rate.sleep()
pub.publish(Twist())
