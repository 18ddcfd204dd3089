"""The ROS 2 package `builtin_interfaces` for student code: msg."""
