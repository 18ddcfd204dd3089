"""geometry_msgs: points, vectors, poses and velocities (definitions as in ros/common_msgs)."""

from __future__ import annotations

from . import std_msgs as _std_msgs  # noqa: F401  # registers std_msgs/Header used below
from ._core import Message


class Vector3(Message):
    """A vector in free space; use Point for positions."""

    _type = "geometry_msgs/Vector3"
    _definition = """
# This represents a vector in free space.
float64 x
float64 y
float64 z
"""


class Point(Message):
    _type = "geometry_msgs/Point"
    _definition = """
# This contains the position of a point in free space
float64 x
float64 y
float64 z
"""


class Quaternion(Message):
    _type = "geometry_msgs/Quaternion"
    _definition = """
# This represents an orientation in free space in quaternion form.

float64 x
float64 y
float64 z
float64 w
"""


class Pose(Message):
    _type = "geometry_msgs/Pose"
    _definition = """
# A representation of pose in free space, composed of position and orientation.
Point position
Quaternion orientation
"""


class Pose2D(Message):
    _type = "geometry_msgs/Pose2D"
    _definition = """
# This expresses a position and orientation on a 2D manifold.

float64 x
float64 y
float64 theta
"""


class PoseStamped(Message):
    _type = "geometry_msgs/PoseStamped"
    _definition = """
# A Pose with reference coordinate frame and timestamp
Header header
Pose pose
"""


class PoseWithCovariance(Message):
    _type = "geometry_msgs/PoseWithCovariance"
    _definition = """
# This represents a pose in free space with uncertainty.

Pose pose

# Row-major representation of the 6x6 covariance matrix
# The orientation parameters use a fixed-axis representation.
# In order, the parameters are:
# (x, y, z, rotation about X axis, rotation about Y axis, rotation about Z axis)
float64[36] covariance
"""


class Twist(Message):
    """Linear [m/s] and angular [rad/s] velocity."""

    _type = "geometry_msgs/Twist"
    _definition = """
# This expresses velocity in free space broken into its linear and angular parts.
Vector3  linear
Vector3  angular
"""


class TwistWithCovariance(Message):
    _type = "geometry_msgs/TwistWithCovariance"
    _definition = """
# This expresses velocity in free space with uncertainty.

Twist twist

# Row-major representation of the 6x6 covariance matrix
# The orientation parameters use a fixed-axis representation.
# In order, the parameters are:
# (x, y, z, rotation about X axis, rotation about Y axis, rotation about Z axis)
float64[36] covariance
"""


class Transform(Message):
    """A rigid transform: translation [m] then rotation (unit quaternion)."""

    _type = "geometry_msgs/Transform"
    _definition = """
# This represents the transform between two coordinate frames in free space.

Vector3 translation
Quaternion rotation
"""


class TransformStamped(Message):
    """The pose of frame ``child_frame_id`` in frame ``header.frame_id`` (what tf publishes)."""

    _type = "geometry_msgs/TransformStamped"
    _definition = """
# This expresses a transform from coordinate frame header.frame_id
# to the coordinate frame child_frame_id
#
# This message is mostly used by the
# <a href="http://wiki.ros.org/tf">tf</a> package.
# See its documentation for more information.

Header header
string child_frame_id # the frame id of the child frame
Transform transform
"""
