"""The ROS 2 package `tf2_msgs` for student code: msg."""
