"""The ROS 2 package `std_srvs` for student code: srv."""
