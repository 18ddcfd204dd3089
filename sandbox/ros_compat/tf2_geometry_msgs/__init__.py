"""`tf2_geometry_msgs` for student code: do_transform_point / vector3 / pose / wrench, and the
registrations that let tf2_ros's buffer.transform() take geometry_msgs stamped messages."""

from .tf2_geometry_msgs import (
    do_transform_point,
    do_transform_polygon_stamped,
    do_transform_pose,
    do_transform_pose_stamped,
    do_transform_pose_with_covariance_stamped,
    do_transform_quaternion,
    do_transform_vector3,
    do_transform_wrench,
    from_msg_msg,
    to_msg_msg,
)

__all__ = [
    "do_transform_point",
    "do_transform_polygon_stamped",
    "do_transform_pose",
    "do_transform_pose_stamped",
    "do_transform_pose_with_covariance_stamped",
    "do_transform_quaternion",
    "do_transform_vector3",
    "do_transform_wrench",
    "from_msg_msg",
    "to_msg_msg",
]
