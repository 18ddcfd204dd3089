#!/usr/bin/env python3
# Course pattern: the rospy_tutorials AddTwoInts client (a custom .srv package we do not have).
import sys

import rospy
from rospy_tutorials.srv import AddTwoInts


def add_two_ints_client(x, y):
    rospy.wait_for_service("add_two_ints")
    try:
        add_two_ints = rospy.ServiceProxy("add_two_ints", AddTwoInts)
        return add_two_ints(x, y).sum
    except rospy.ServiceException as e:
        print("Service call failed: %s" % e)  # noqa: UP031


if __name__ == "__main__":
    rospy.init_node("add_two_ints_client")
    print("%s + %s = %s" % (1, 2, add_two_ints_client(1, 2)))  # noqa: UP031
    sys.exit(0)
