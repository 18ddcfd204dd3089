#!/usr/bin/env python3
# Course pattern: read a motion plan from a CSV next to the script, log odometry to a CSV.
import csv
import time

import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

pose = None


def odom_callback(msg):
    global pose
    pose = (msg.header.stamp.to_sec(), msg.pose.pose.position.x, msg.pose.pose.position.y)


rospy.init_node("waypoint_driver")
pub = rospy.Publisher("cmd_vel", Twist, queue_size=10)
rospy.Subscriber("odom", Odometry, odom_callback)

with open("segments.csv") as f:
    segments = [
        (float(row["linear"]), float(row["angular"]), float(row["seconds"]))
        for row in csv.DictReader(f)
    ]
rospy.loginfo("loaded %d segments", len(segments))

log = []
for linear, angular, seconds in segments:
    cmd = Twist()
    cmd.linear.x = linear
    cmd.angular.z = angular
    start = time.time()
    while time.time() - start < seconds:
        pub.publish(cmd)
        if pose is not None:
            log.append(pose)
        time.sleep(0.05)
pub.publish(Twist())

with open("trajectory.csv", "w", newline="") as f:
    writer = csv.writer(f)
    writer.writerow(["t", "x", "y"])
    writer.writerows(log)
rospy.loginfo("wrote %d poses", len(log))
