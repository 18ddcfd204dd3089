"""The ROS 1 package `std_msgs` for student code: `std_msgs.msg`."""
