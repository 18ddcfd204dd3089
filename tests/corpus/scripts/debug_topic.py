#!/usr/bin/env python3
# Course pattern: publish the controller's error on a debug topic that nobody subscribes to.
import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Float32, Int32

distance = None


def on_distance(msg):
    global distance
    if msg.data > 0:
        distance = msg.data / 100.0


rospy.init_node("p_approach")
cmd_pub = rospy.Publisher("Control", Twist, queue_size=1)
debug_pub = rospy.Publisher("debug/error", Float32, queue_size=10)
rospy.Subscriber("Distance", Int32, on_distance)
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    if distance is not None:
        error = distance - 0.3
        cmd = Twist()
        cmd.linear.x = max(-0.1, min(0.1, 0.8 * error))
        cmd_pub.publish(cmd)
        debug_pub.publish(Float32(error))
    rate.sleep()
