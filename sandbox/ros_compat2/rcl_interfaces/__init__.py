"""The ROS 2 package `rcl_interfaces` for student code: msg, srv."""
