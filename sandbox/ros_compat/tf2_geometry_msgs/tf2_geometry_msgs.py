"""Transforming geometry_msgs stamped messages with a TransformStamped, and their registration
with tf2_ros so that `buffer.transform(pose_stamped, "map")` works once this is imported.

As ros/geometry2's tf2_geometry_msgs (noetic): do_transform_point / _vector3 / _pose / _wrench
return a new message whose header is the transform's (frame_id = the target frame); a vector
is only rotated. Added here: do_transform_pose also takes a bare Pose (returning a Pose, as
ROS 2 does), do_transform_pose_stamped, do_transform_quaternion and
do_transform_pose_with_covariance_stamped (pose only; the covariance is rotated too).
"""

from __future__ import annotations

import copy
from typing import Any

import tf2_ros
from tf2_ros import _math


def _pose_of(transform: Any) -> _math.Pose:
    if getattr(transform, "_type", None) != "geometry_msgs/TransformStamped":
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
    """A PoseStamped (ROS 1) or a bare Pose (ROS 2 style) in the transform's target frame."""
    if getattr(pose, "_type", None) == "geometry_msgs/Pose":
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


def to_msg_msg(msg: Any) -> Any:
    return msg


def from_msg_msg(msg: Any) -> Any:
    return msg


_TRANSFORMS = {
    "geometry_msgs/PointStamped": do_transform_point,
    "geometry_msgs/Vector3Stamped": do_transform_vector3,
    "geometry_msgs/QuaternionStamped": do_transform_quaternion,
    "geometry_msgs/PoseStamped": do_transform_pose_stamped,
    "geometry_msgs/PoseWithCovarianceStamped": do_transform_pose_with_covariance_stamped,
    "geometry_msgs/WrenchStamped": do_transform_wrench,
}
for _type_name, _function in _TRANSFORMS.items():
    tf2_ros.TransformRegistration().add(_type_name, _function)
for _type_name in ("geometry_msgs/Vector3Stamped", "geometry_msgs/PoseStamped",
                   "geometry_msgs/PointStamped"):  # fmt: skip
    tf2_ros.ConvertRegistration().add_to_msg(_type_name, to_msg_msg)
    tf2_ros.ConvertRegistration().add_from_msg(_type_name, from_msg_msg)
