"""The ROS 2 package `unique_identifier_msgs` for student code: msg."""
