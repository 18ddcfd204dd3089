"""The ROS 2 package `visualization_msgs` for student code: msg."""
