"""Directory of importable ROS 1 look-alike packages for student code.

The node host puts this directory itself (not its parent) on sys.path, so that student code
imports `rospy`, `std_msgs.msg`, `geometry_msgs.msg`, `sensor_msgs.msg` and `nav_msgs.msg` as
top-level packages. This file only makes the directory a package for packaging tools; nothing
imports `sandbox.ros_compat` itself.
"""
