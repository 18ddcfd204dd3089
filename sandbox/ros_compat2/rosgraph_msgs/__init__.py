"""The ROS 2 package `rosgraph_msgs` for student code: msg."""
