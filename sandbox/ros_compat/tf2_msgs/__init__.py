"""The ROS 1 package `tf2_msgs` for student code: `tf2_msgs.msg` and `tf2_msgs.srv`."""
