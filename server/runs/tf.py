"""The transform tree a recording carries on ``/tf``, so Foxglove's 3D panel can place every
sensor message (REP 105 frame names: ``map`` is the world, ``base_link`` the robot's body).

The tree stays a tree: ``map -> base_link`` is the true pose, ``base_link -> <sensor frame>``
the fixed mounts, and, only when asked for, ``map -> odom`` fixed at the pose where the wheel
odometry started, so ``nav_msgs/Odometry`` (pose in ``odom``) is drawn where dead reckoning
believes the robot is. There is no ``odom -> base_link``: it would give ``base_link`` two
parents.

A sensor frame is ``(x [m], y [m], yaw [rad])`` in the robot frame (x forward, y left, yaw
counter-clockwise), or ``(x, y, yaw, roll [rad])``. The roll is for scanners whose angles grow
clockwise, like the crop rover's YDLidar X2 (0 rad at the rear, robot direction = pi - angle):
``(0.0, 0.0, math.pi, math.pi)`` mounts that frame upside down and turned around, which maps a
beam at lidar angle a to the robot direction pi - a, as the sensor defines it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from sandbox.msgs import Time
from sandbox.msgs.geometry_msgs import Quaternion, Transform, TransformStamped, Vector3
from sandbox.msgs.std_msgs import Header
from sandbox.msgs.tf2_msgs import TFMessage

MAP_FRAME = "map"
ODOM_FRAME = "odom"
BASE_FRAME = "base_link"

SensorFrame = tuple[float, float, float] | tuple[float, float, float, float]


def _quaternion(yaw_rad: float, roll_rad: float = 0.0) -> Quaternion:
    """Rotation by `yaw_rad` about z, then `roll_rad` about the turned x axis (q_yaw * q_roll)."""
    cos_yaw, sin_yaw = math.cos(0.5 * yaw_rad), math.sin(0.5 * yaw_rad)
    cos_roll, sin_roll = math.cos(0.5 * roll_rad), math.sin(0.5 * roll_rad)
    return Quaternion(
        x=cos_yaw * sin_roll, y=sin_yaw * sin_roll, z=sin_yaw * cos_roll, w=cos_yaw * cos_roll
    )


def _stamped(stamp: Time, parent: str, child: str, pose: SensorFrame) -> TransformStamped:
    if len(pose) not in (3, 4):
        raise ValueError(
            f"frame '{child}': give (x [m], y [m], yaw [rad]) or (x, y, yaw, roll [rad]), "
            f"got {pose!r}"
        )
    x_m, y_m, yaw_rad = (float(value) for value in pose[:3])
    roll_rad = float(pose[3]) if len(pose) == 4 else 0.0
    if not all(math.isfinite(value) for value in (x_m, y_m, yaw_rad, roll_rad)):
        raise ValueError(f"frame '{child}': pose must be finite numbers, got {pose!r}")
    return TransformStamped(
        header=Header(stamp=stamp, frame_id=parent),
        child_frame_id=child,
        transform=Transform(Vector3(x_m, y_m, 0.0), _quaternion(yaw_rad, roll_rad)),
    )


def tf_message(
    time_ns: int,
    pose_x: float,
    pose_y: float,
    pose_yaw: float,
    sensor_frames: Mapping[str, SensorFrame],
    *,
    odom_origin: tuple[float, float, float] | None = None,
) -> TFMessage:
    """The ``/tf`` message at run time `time_ns` [ns]: ``map -> base_link`` at the true pose
    (x [m], y [m], yaw [rad]), ``base_link -> frame`` for each of `sensor_frames` (see the
    module docstring) and, if `odom_origin` (x, y, yaw in the map) is given, ``map -> odom``.

    Every transform carries the same stamp; the run engine records one of these at ~30 Hz."""
    stamp = Time.from_nsec(int(time_ns))
    transforms = [_stamped(stamp, MAP_FRAME, BASE_FRAME, (pose_x, pose_y, pose_yaw))]
    if odom_origin is not None:
        transforms.append(_stamped(stamp, MAP_FRAME, ODOM_FRAME, odom_origin))
    for frame, mount in sensor_frames.items():
        if frame in (MAP_FRAME, ODOM_FRAME, BASE_FRAME):
            raise ValueError(
                f"sensor frame '{frame}' would give '{frame}' a second parent; sensor frames "
                f"hang below '{BASE_FRAME}' and need names of their own"
            )
        transforms.append(_stamped(stamp, BASE_FRAME, frame, mount))
    return TFMessage(transforms=transforms)
