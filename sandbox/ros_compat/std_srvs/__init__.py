"""The ROS 1 package `std_srvs` for student code: `std_srvs.srv`."""
