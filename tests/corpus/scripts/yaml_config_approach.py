#!/usr/bin/env python3
# Course pattern: controller gains read from a YAML file in the working directory.
import rospy
import yaml
from geometry_msgs.msg import Twist
from std_msgs.msg import Int32

with open("approach.yaml") as f:
    config = yaml.safe_load(f)

setpoint = config["setpoint_m"]
kp = config["gains"]["kp"]
max_speed = config["max_speed"]

distance = None


def on_distance(msg):
    global distance
    if msg.data > 0:
        distance = msg.data / 100.0


rospy.init_node("yaml_approach")
rospy.loginfo("config: %s" % config)  # noqa: UP031
pub = rospy.Publisher("Control", Twist, queue_size=1)
rospy.Subscriber("Distance", Int32, on_distance)
rate = rospy.Rate(config["rate_hz"])
while not rospy.is_shutdown():
    cmd = Twist()
    if distance is not None:
        cmd.linear.x = max(-max_speed, min(max_speed, kp * (distance - setpoint)))
    pub.publish(cmd)
    rate.sleep()
