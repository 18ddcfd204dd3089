"""`sensor_msgs_py` for ROS 2 student code (ros2/common_interfaces): `point_cloud2`, reading
and building sensor_msgs/msg/PointCloud2 with numpy."""
