#!/usr/bin/env python3
# Course pattern: a TurtleBot3 right-wall follower whose loop never sleeps (scan[270] = right).
import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan

DESIRED_DISTANCE = 0.45
FORWARD_SPEED = 0.15
KP = 1.5

right_distance = None
front_distance = None


def scan_callback(scan):
    global right_distance, front_distance
    right = [r for r in scan.ranges[260:281] if scan.range_min < r < scan.range_max]
    front = [r for r in scan.ranges[-15:] + scan.ranges[:16] if scan.range_min < r < scan.range_max]
    right_distance = min(right) if right else scan.range_max
    front_distance = min(front) if front else scan.range_max


rospy.init_node("wall_follower")
cmd_pub = rospy.Publisher("cmd_vel", Twist, queue_size=10)
rospy.Subscriber("scan", LaserScan, scan_callback)

twist = Twist()
while not rospy.is_shutdown():
    if right_distance is None:
        continue
    if front_distance < 0.4:
        twist.linear.x = 0.0
        twist.angular.z = 0.5
    else:
        error = DESIRED_DISTANCE - right_distance
        twist.linear.x = FORWARD_SPEED
        twist.angular.z = max(-0.5, min(0.5, KP * error))
    cmd_pub.publish(twist)
