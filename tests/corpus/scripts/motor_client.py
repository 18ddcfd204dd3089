#!/usr/bin/env python3
# Course pattern: a service client node (wait_for_service, ServiceProxy, call and read reply).
import rospy
from std_srvs.srv import Empty, SetBool, SetBoolRequest, Trigger

rospy.init_node("motor_client")
rospy.wait_for_service("enable_motors", timeout=5)
rospy.wait_for_service("read_distance", timeout=5)
enable = rospy.ServiceProxy("enable_motors", SetBool)
read_distance = rospy.ServiceProxy("read_distance", Trigger)
beep = rospy.ServiceProxy("beep", Empty)

try:
    reply = enable(True)
    rospy.loginfo("server says: %s", reply.message)
    rospy.sleep(2.0)
    rospy.loginfo("distance now %s", read_distance().message)
    reply = enable(SetBoolRequest(data=False))
    rospy.loginfo("server says: %s", reply.message)
    beep()
except rospy.ServiceException as e:
    rospy.logerr("service call failed: %s" % e)  # noqa: UP031
