#!/usr/bin/env python3
# Course pattern: a helper node in a namespace (<group ns>) publishing a relative topic.
import rospy
from std_msgs.msg import Bool, Int32

rospy.init_node("range_monitor")
threshold_cm = rospy.get_param("~threshold_cm", 40)
pub = rospy.Publisher("too_close", Bool, queue_size=10)
rospy.loginfo("namespace %s, publishing %s", rospy.get_namespace(), pub.resolved_name)


def on_range(msg):
    pub.publish(Bool(0 < msg.data < threshold_cm))


rospy.Subscriber("range", Int32, on_range)
rospy.spin()
