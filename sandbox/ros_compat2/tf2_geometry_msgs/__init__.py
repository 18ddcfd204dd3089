"""`tf2_geometry_msgs` for ROS 2 student code: do_transform_point / vector3 / pose /
pose_stamped / pose_with_covariance_stamped / polygon_stamped (and wrench, quaternion), shared
with ROS 1 (sandbox/tf2/geometry.py) and registered with tf2_ros under the ROS 2 type names, so
that `buffer.transform(pose_stamped, "map")` works once this is imported. As in ROS 2,
do_transform_pose takes a bare geometry_msgs/msg/Pose and returns a Pose."""

import tf2_ros

from sandbox.tf2.geometry import (
    CONVERTIBLE,
    TRANSFORMS,
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

for _name, _function in TRANSFORMS.items():
    tf2_ros.TransformRegistration().add(f"geometry_msgs/msg/{_name}", _function)
for _name in CONVERTIBLE:
    tf2_ros.ConvertRegistration().add_to_msg(f"geometry_msgs/msg/{_name}", to_msg_msg)
    tf2_ros.ConvertRegistration().add_from_msg(f"geometry_msgs/msg/{_name}", from_msg_msg)
