#!/usr/bin/env python3
# Course pattern: an old-style script (roslib.load_manifest) that moves open-loop with rospy.sleep.
import roslib

roslib.load_manifest("my_robot_teleop")
import rospy  # noqa: E402
from geometry_msgs.msg import Twist  # noqa: E402

rospy.init_node("open_loop")
pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)
rospy.sleep(0.5)  # let the connections come up

forward = Twist()
forward.linear.x = 0.1
pub.publish(forward)
rospy.sleep(2.0)
pub.publish(Twist())
rospy.loginfo("open loop move done")
rospy.spin()
