"""Small frame and message helpers shared by the sensors, so the math lives in one place
(where a sensor sits on the robot is `server.sim.sensors.mount.Mount`).

Conventions (REP 103): x forward, y left, yaw counter-clockwise from +x [rad]; angles are
reported wrapped to (-pi, pi] (`server.sim.kinematics.wrap_angle`).
"""

from __future__ import annotations

import math

from sandbox.msgs import Time
from sandbox.msgs.geometry_msgs import Quaternion
from sandbox.msgs.std_msgs import Header
from server.sim.geometry import yaw_quaternion

TWO_PI = 2.0 * math.pi


def yaw_orientation(yaw_rad: float) -> Quaternion:
    """The geometry_msgs/Quaternion of a rotation by `yaw_rad` [rad] about +z."""
    return Quaternion(*yaw_quaternion(yaw_rad))


def stamped_header(time_s: float, frame_id: str) -> Header:
    """A message header stamped with the simulated time [s]."""
    return Header(stamp=Time.from_sec(float(time_s)), frame_id=frame_id)


def diagonal_covariance(variances: tuple[float, ...]) -> list[float]:
    """A row-major n x n covariance (ROS `float64[n*n]`) with `variances` on the diagonal."""
    size = len(variances)
    flat = [0.0] * (size * size)
    for index, variance in enumerate(variances):
        flat[index * size + index] = float(variance)
    return flat
