"""The ROS 2 package `nav_msgs` for student code: msg, srv."""
