"""The ROS 1 package `visualization_msgs` for student code: `visualization_msgs.msg`."""
