#!/usr/bin/env python3
# Course pattern: a purely reactive node that publishes from inside the subscriber callback.
import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32

pub = None


def callback(msg):
    cmd = Twist()
    if msg.data > 35 or msg.data == 0:
        cmd.linear.x = 0.08
    pub.publish(cmd)


def main():
    global pub
    rospy.init_node("reactive")
    pub = rospy.Publisher("Control", Twist, queue_size=1)
    rospy.Subscriber("Distance", Int32, callback)
    rospy.spin()


if __name__ == "__main__":
    main()
