#!/usr/bin/env python3
# Course pattern: rospy.wait_for_message before the control loop (make sure sensors are up).
import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan

rospy.init_node("wait_for_scan")
pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)
start = rospy.get_time()
try:
    scan = rospy.wait_for_message("scan", LaserScan, timeout=5)
except rospy.ROSException:
    rospy.logerr("no laser scan within 5 s")
    raise
rospy.loginfo(
    "first scan after %.2f s with %d beams" % (rospy.get_time() - start, len(scan.ranges))  # noqa: UP031
)

rate = rospy.Rate(10)
cmd = Twist()
cmd.linear.x = 0.2
while not rospy.is_shutdown():
    pub.publish(cmd)
    rate.sleep()
