"""The ROS 1 package `actionlib_msgs` for student code: `actionlib_msgs.msg`."""
