"""The ROS 1 package `geometry_msgs` for student code: `geometry_msgs.msg`."""
