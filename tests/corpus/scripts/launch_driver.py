#!/usr/bin/env python3
# Course pattern: a node configured from a launch file (<param>, <rosparam>, <remap>, <arg>).
import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32

rospy.init_node("driver")
speed = rospy.get_param("~speed")
stop_distance = float(rospy.get_param("~stop_distance"))
kp = rospy.get_param("~gains/kp")
robot_name = rospy.get_param("/robot_name")
rospy.loginfo(
    "%s: speed %.2f, stop at %.2f m, kp %.2f" % (robot_name, speed, stop_distance, kp)  # noqa: UP031
)

distance = None


def on_range(msg):
    global distance
    if msg.data > 0:
        distance = msg.data / 100.0


rospy.Subscriber("range", Int32, on_range)
pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    cmd = Twist()
    if distance is not None:
        cmd.linear.x = max(-speed, min(speed, kp * (distance - stop_distance)))
    pub.publish(cmd)
    rate.sleep()
