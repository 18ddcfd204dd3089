#!/usr/bin/env python3
# Course pattern: rospy.Timer callbacks drive the robot while the main thread spins.
import rospy
from geometry_msgs.msg import Twist

ticks = 0


def control_tick(event):
    global ticks
    ticks += 1
    cmd = Twist()
    cmd.linear.x = 0.1
    pub.publish(cmd)
    if event.last_real is not None:
        period = (event.current_real - event.last_real).to_sec()
        rospy.loginfo_throttle(1.0, "timer period %.3f s" % period)  # noqa: UP031


def stop(event):
    control_timer.shutdown()
    pub.publish(Twist())
    rospy.loginfo("stopped after %d ticks", ticks)


rospy.init_node("timer_driver")
pub = rospy.Publisher("Control", Twist, queue_size=10)
control_timer = rospy.Timer(rospy.Duration(0.1), control_tick)
rospy.Timer(rospy.Duration(2.0), stop, oneshot=True)
rospy.spin()
