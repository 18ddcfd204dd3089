"""`tf.transformations` for student code, with the names and conventions of the module ROS 1
ships in the `tf` package (C. Gohlke's transformations.py): quaternions are [x, y, z, w]; Euler
conventions are the 24 axes strings such as 'sxyz' (the default: roll, pitch, yaw about the
static x, y, z axes); angles are in radians; results are numpy arrays.

    from tf.transformations import euler_from_quaternion, quaternion_from_euler
    q = msg.pose.pose.orientation
    roll, pitch, yaw = euler_from_quaternion([q.x, q.y, q.z, q.w])

The math lives in sandbox/transformations, shared with ROS 2's tf_transformations.
"""

from sandbox.transformations import *  # noqa: F403
from sandbox.transformations import (  # noqa: F401  (scripts read these private names)
    _AXES2TUPLE,
    _EPS,
    _NEXT_AXIS,
    _TUPLE2AXES,
    __all__,
)
