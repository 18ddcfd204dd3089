"""The ROS 2 package `action_tutorials_interfaces` for student code: action."""
