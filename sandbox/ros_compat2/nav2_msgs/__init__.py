"""The ROS 2 package `nav2_msgs` for student code: msg, action."""
