"""The ROS 2 package `service_msgs` for student code: msg."""
