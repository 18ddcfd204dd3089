"""The ROS 2 package `example_interfaces` for student code: msg, srv, action."""
