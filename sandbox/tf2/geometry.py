"""Transforming geometry_msgs stamped messages with a TransformStamped: the do_transform_*
functions of tf2_geometry_msgs, for ROS 1 and ROS 2 message classes alike (their fields are
the same; only the type names differ, "geometry_msgs/Pose" and "geometry_msgs/msg/Pose").

As ros/geometry2's tf2_geometry_msgs: do_transform_point / _vector3 / _pose_stamped / _wrench
return a new message whose header is the transform's (frame_id = the target frame); a vector is
only rotated; ROS 2's do_transform_pose takes a bare Pose and returns a Pose, ROS 1's takes a
PoseStamped (both accepted here); do_transform_pose_with_covariance_stamped rotates the 6x6
covariance too; do_transform_polygon_stamped moves every corner (ROS 2). The registrations
with tf2_ros live in each dialect's tf2_geometry_msgs package.
"""

from __future__ import annotations

import copy
from typing import Any

from . import _math

# The ROS 1 and ROS 2 names of the message types this module reads.
_TRANSFORM_TYPES = ("geometry_msgs/TransformStamped", "geometry_msgs/msg/TransformStamped")
_POSE_TYPES = ("geometry_msgs/Pose", "geometry_msgs/msg/Pose")


def _pose_of(transform: Any) -> _math.Pose:
    if getattr(transform, "_type", None) not in _TRANSFORM_TYPES:
        raise TypeError(
            "the transform argument is a geometry_msgs/TransformStamped, such as "
            f"buffer.lookup_transform(...) returns; got {transform!r}"
        )
    t, r = transform.transform.translation, transform.transform.rotation
    return ((t.x, t.y, t.z), (r.x, r.y, r.z, r.w))


def _stamped_result(message: Any, transform: Any) -> Any:
    result = type(message)()
    result.header = copy.deepcopy(transform.header)
    return result


def _apply_to_pose(pose: Any, frame: _math.Pose) -> Any:
    """A new Pose: `pose` moved by `frame`."""
    p, o = pose.position, pose.orientation
    (x, y, z), (qx, qy, qz, qw) = _math.compose(frame, ((p.x, p.y, p.z), (o.x, o.y, o.z, o.w)))
    result = type(pose)()
    result.position.x, result.position.y, result.position.z = x, y, z
    result.orientation.x, result.orientation.y = qx, qy
    result.orientation.z, result.orientation.w = qz, qw
    return result


def do_transform_point(point: Any, transform: Any) -> Any:
    """A geometry_msgs/PointStamped in the transform's target frame."""
    frame = _pose_of(transform)
    p = point.point
    moved = _math.compose(frame, ((p.x, p.y, p.z), (0.0, 0.0, 0.0, 1.0)))[0]
    result = _stamped_result(point, transform)
    result.point.x, result.point.y, result.point.z = moved
    return result


def do_transform_vector3(vector3: Any, transform: Any) -> Any:
    """A geometry_msgs/Vector3Stamped rotated into the target frame (no translation)."""
    _, rotation = _pose_of(transform)
    v = vector3.vector
    result = _stamped_result(vector3, transform)
    result.vector.x, result.vector.y, result.vector.z = _math.rotate(rotation, (v.x, v.y, v.z))
    return result


def do_transform_quaternion(quaternion: Any, transform: Any) -> Any:
    """A geometry_msgs/QuaternionStamped turned into the target frame."""
    _, rotation = _pose_of(transform)
    q = quaternion.quaternion
    x, y, z, w = _math.multiply(rotation, (q.x, q.y, q.z, q.w))
    result = _stamped_result(quaternion, transform)
    result.quaternion.x, result.quaternion.y = x, y
    result.quaternion.z, result.quaternion.w = z, w
    return result


def do_transform_pose_stamped(pose: Any, transform: Any) -> Any:
    """A geometry_msgs/PoseStamped in the transform's target frame."""
    result = _stamped_result(pose, transform)
    result.pose = _apply_to_pose(pose.pose, _pose_of(transform))
    return result


def do_transform_pose(pose: Any, transform: Any) -> Any:
    """A bare Pose (ROS 2) or a PoseStamped (ROS 1) in the transform's target frame."""
    if getattr(pose, "_type", None) in _POSE_TYPES:
        return _apply_to_pose(pose, _pose_of(transform))
    return do_transform_pose_stamped(pose, transform)


def do_transform_pose_with_covariance_stamped(pose: Any, transform: Any) -> Any:
    """A geometry_msgs/PoseWithCovarianceStamped in the target frame; the 6x6 covariance is
    rotated (position and orientation blocks alike)."""
    frame = _pose_of(transform)
    result = _stamped_result(pose, transform)
    result.pose.pose = _apply_to_pose(pose.pose.pose, frame)
    rotation = [_math.rotate(frame[1], axis) for axis in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
    r3 = [[rotation[col][row] for col in range(3)] for row in range(3)]
    r6 = [[0.0] * 6 for _ in range(6)]
    for row in range(3):
        for col in range(3):
            r6[row][col] = r6[row + 3][col + 3] = r3[row][col]
    cov = [list(pose.pose.covariance[6 * row : 6 * row + 6]) for row in range(6)]
    rc = [[sum(r6[i][k] * cov[k][j] for k in range(6)) for j in range(6)] for i in range(6)]
    result.pose.covariance = [
        sum(rc[i][k] * r6[j][k] for k in range(6)) for i in range(6) for j in range(6)
    ]
    return result


def do_transform_wrench(wrench: Any, transform: Any) -> Any:
    """A geometry_msgs/WrenchStamped: force and torque rotated into the target frame."""
    _, rotation = _pose_of(transform)
    result = _stamped_result(wrench, transform)
    for name in ("force", "torque"):
        v = getattr(wrench.wrench, name)
        out = getattr(result.wrench, name)
        out.x, out.y, out.z = _math.rotate(rotation, (v.x, v.y, v.z))
    return result


def do_transform_polygon_stamped(polygon: Any, transform: Any) -> Any:
    """A geometry_msgs/PolygonStamped with every corner in the target frame."""
    frame = _pose_of(transform)
    result = _stamped_result(polygon, transform)
    for corner in polygon.polygon.points:
        moved = copy.copy(corner)
        x, y, z = _math.compose(frame, ((corner.x, corner.y, corner.z), (0.0, 0.0, 0.0, 1.0)))[0]
        moved.x, moved.y, moved.z = x, y, z
        result.polygon.points.append(moved)
    return result


def to_msg_msg(msg: Any) -> Any:
    return msg


def from_msg_msg(msg: Any) -> Any:
    return msg


# Which function transforms each stamped type, by the type's name without its package.
TRANSFORMS = {
    "PointStamped": do_transform_point,
    "Vector3Stamped": do_transform_vector3,
    "QuaternionStamped": do_transform_quaternion,
    "PoseStamped": do_transform_pose_stamped,
    "PoseWithCovarianceStamped": do_transform_pose_with_covariance_stamped,
    "WrenchStamped": do_transform_wrench,
    "PolygonStamped": do_transform_polygon_stamped,
}
CONVERTIBLE = ("Vector3Stamped", "PoseStamped", "PointStamped")  # to_msg/from_msg: themselves
