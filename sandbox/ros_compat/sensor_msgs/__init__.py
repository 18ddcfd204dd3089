"""The ROS 1 package `sensor_msgs` for student code: `sensor_msgs.msg` and `sensor_msgs.srv`."""
