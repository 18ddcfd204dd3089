"""tf2's BufferCore for ROS 1 (tf2_py): the shared core of sandbox/tf2 in the ROS 1 dialect
(rospy.Time and rospy.Duration, geometry_msgs/TransformStamped)."""

from sandbox.tf2.buffer_core import BufferCore, to_nsec

__all__ = ["BufferCore", "to_nsec"]
