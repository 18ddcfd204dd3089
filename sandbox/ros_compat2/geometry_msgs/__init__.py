"""The ROS 2 package `geometry_msgs` for student code: msg."""
