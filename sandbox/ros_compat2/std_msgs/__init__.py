"""The ROS 2 package `std_msgs` for student code: msg."""
