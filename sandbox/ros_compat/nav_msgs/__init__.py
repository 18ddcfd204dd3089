"""The ROS 1 package `nav_msgs` for student code: `nav_msgs.msg` and `nav_msgs.srv`."""
