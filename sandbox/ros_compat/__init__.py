"""Directory of importable ROS 1 look-alike packages for student code.

The node host puts this directory itself (not its parent) on sys.path, so that student code
imports `rospy`, `roslib`, `tf`, `tf2_ros` and the message packages (`std_msgs.msg`,
`std_srvs.srv`, `visualization_msgs.msg`... one directory per package of sandbox.msgs) as
top-level packages. This file only makes the directory a package for packaging tools; nothing
imports `sandbox.ros_compat` itself.
"""
