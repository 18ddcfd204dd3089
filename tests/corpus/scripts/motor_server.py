#!/usr/bin/env python3
# Course pattern: a service server node (std_srvs SetBool, Trigger and Empty) owning the motors.
import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Bool, Int32
from std_srvs.srv import (
    Empty,
    EmptyResponse,
    SetBool,
    SetBoolResponse,
    Trigger,
    TriggerResponse,
)

enabled = False
distance_cm = 0


def on_distance(msg):
    global distance_cm
    distance_cm = msg.data


def handle_enable(req):
    global enabled
    enabled = req.data
    rospy.loginfo("enable_motors(%s)", req.data)
    return SetBoolResponse(success=True, message="motors on" if enabled else "motors off")


def handle_read(req):
    return TriggerResponse(success=True, message="%d cm" % distance_cm)  # noqa: UP031


def handle_beep(req):
    buzzer.publish(Bool(True))
    return EmptyResponse()


rospy.init_node("motor_server")
control = rospy.Publisher("Control", Twist, queue_size=1)
buzzer = rospy.Publisher("Buzzer", Bool, queue_size=1)
rospy.Subscriber("Distance", Int32, on_distance)
rospy.Service("enable_motors", SetBool, handle_enable)
rospy.Service("read_distance", Trigger, handle_read)
rospy.Service("beep", Empty, handle_beep)
rospy.loginfo("motor server ready")

rate = rospy.Rate(10)
while not rospy.is_shutdown():
    cmd = Twist()
    if enabled:
        cmd.linear.x = 0.1
    control.publish(cmd)
    rate.sleep()
