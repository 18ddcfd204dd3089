"""`tf_transformations` for ROS 2 student code (the package DLu/tf_transformations, which ROS 2
distributions ship in place of ROS 1's tf.transformations): the same functions, names and
conventions (quaternions [x, y, z, w], the 24 Euler axes strings, 'sxyz' by default, radians).

    from tf_transformations import euler_from_quaternion, quaternion_from_euler
    q = msg.pose.pose.orientation
    roll, pitch, yaw = euler_from_quaternion([q.x, q.y, q.z, q.w])

The ROS 2 package computes through transforms3d, which shows in two places kept here:
quaternion_from_euler, quaternion_about_axis, quaternion_from_matrix and quaternion_multiply
return a tuple (x, y, z, w) rather than a numpy array, and quaternion_from_matrix returns the
quaternion with w >= 0. Everything else is the shared implementation in sandbox/transformations,
the one ROS 1's tf.transformations uses.
"""

from __future__ import annotations

from typing import Any

from sandbox import transformations as _shared
from sandbox.transformations import *  # noqa: F403
from sandbox.transformations import (  # noqa: F401  (scripts read these private names)
    _AXES2TUPLE,
    _EPS,
    _NEXT_AXIS,
    _TUPLE2AXES,
    __all__,
)

Quaternion = tuple[float, float, float, float]


def _as_tuple(quaternion: Any) -> Quaternion:
    x, y, z, w = (float(value) for value in quaternion)
    return (x, y, z, w)


def quaternion_from_euler(ai: float, aj: float, ak: float, axes: Any = "sxyz") -> Quaternion:
    """(x, y, z, w) from Euler angles [rad] in convention `axes`."""
    return _as_tuple(_shared.quaternion_from_euler(ai, aj, ak, axes))


def quaternion_about_axis(angle: float, axis: Any) -> Quaternion:
    """(x, y, z, w) of a rotation by `angle` [rad] about `axis`."""
    return _as_tuple(_shared.quaternion_about_axis(angle, axis))


def quaternion_from_matrix(matrix: Any) -> Quaternion:
    """(x, y, z, w), w >= 0, of the rotation part of a 4x4 (or 3x3) matrix."""
    quaternion = _shared.quaternion_from_matrix(matrix)
    return _as_tuple(-quaternion if quaternion[3] < 0.0 else quaternion)


def quaternion_multiply(quaternion1: Any, quaternion0: Any) -> Quaternion:
    """The Hamilton product quaternion1 * quaternion0 as (x, y, z, w)."""
    return _as_tuple(_shared.quaternion_multiply(quaternion1, quaternion0))
