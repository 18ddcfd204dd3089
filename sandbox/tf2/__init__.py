"""tf2's core, shared by ROS 1's and ROS 2's tf2_ros in the sandbox: the frame tree over time
(buffer_core.py over time_cache.py), the exceptions of tf2_py, the transform registries of
tf2_ros's BufferInterface, the rigid-body math (_math.py) and the geometry_msgs transforms of
tf2_geometry_msgs (geometry.py). What differs between the two APIs (time types, message type
names) is a Dialect (dialect.py). Nothing here imports rospy or rclpy: the packages in
sandbox/ros_compat and sandbox/ros_compat2 add subscribing, publishing and waiting.
"""
