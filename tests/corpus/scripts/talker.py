#!/usr/bin/env python3
# Course pattern: the rospy tutorial talker (Publisher created before init_node, anonymous node).
import rospy
from std_msgs.msg import String


def talker():
    pub = rospy.Publisher("chatter", String, queue_size=10)
    rospy.init_node("talker", anonymous=True)
    rate = rospy.Rate(10)  # 10hz
    while not rospy.is_shutdown():
        hello_str = "hello world %s" % rospy.get_time()  # noqa: UP031
        rospy.loginfo(hello_str)
        pub.publish(hello_str)
        rate.sleep()


if __name__ == "__main__":
    try:  # noqa: SIM105
        talker()
    except rospy.ROSInterruptException:
        pass
