"""The ROS 2 package `sensor_msgs` for student code: msg."""
