"""The ROS 2 package `action_msgs` for student code: msg, srv."""
