#!/usr/bin/env python3
# Course pattern: string motor commands timed with rospy.Time/rospy.Duration arithmetic.
import rospy
from std_msgs.msg import String

PLAN = [("forward", 2.0), ("left", 1.0), ("stop", 0.5)]

rospy.init_node("command_sequence")
pub = rospy.Publisher("motor_command", String, queue_size=10)
rate = rospy.Rate(10)
for command, seconds in PLAN:
    rospy.loginfo("%s for %.1f s", command, seconds)
    end_time = rospy.Time.now() + rospy.Duration.from_sec(seconds)
    while not rospy.is_shutdown() and rospy.Time.now() < end_time:
        pub.publish(String(data=command))
        rate.sleep()
rospy.loginfo("sequence finished at t=%.1f", rospy.Time.now().to_sec())
