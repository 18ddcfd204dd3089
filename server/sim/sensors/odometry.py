"""What the iRobot base reports about itself: wheel odometry and the two front bumpers.

Source: 003_4f92d1fa0a49ddae.txt sections 3.1 and 5.5 (the Roomba's serial interface gives
odometry from its wheel encoders and its bumper signals; chapter 6 notes the odometry is "rather
inaccurate"), and the Create Open Interface (notes/protocols.md: packet 7 carries bump-right in
bit 0 and bump-left in bit 1; packets 43/44 the encoder counts).

- `WheelOdometry`: nav_msgs/Odometry, frame "odom", child "base_link". The pose is the
  simulation's `state.odometry_pose`, which it integrates from wheel travel with a small
  wheel-radius/track miscalibration, so it drifts from the true pose; this sensor only reports
  it. The twist comes from the wheel speeds with the NOMINAL geometry the driver believes
  (Create: 72 mm wheels, 235 mm track): v = r (wl + wr) / 2 [m/s], omega = r (wr - wl) / track
  [rad/s]. Covariances are fixed diagonals of the right order; z, roll and pitch, which a planar
  base cannot observe, get 1e6. No extra noise: the error is the integrated miscalibration.
- `Bumper`: std_msgs/Int32MultiArray, data = [left, right], 1 = pressed, from
  `state.contact_angles_rad` (robot frame, 0 ahead, + left). A contact in (0, +90] degrees
  presses left, in [-90, 0] right, and one within 10 degrees of straight ahead presses both (the
  bumper is one shell on two switches); contacts behind the axle press nothing.
- Rate: 20 Hz for both (the driver's sensor-stream polling; assumption). Units SI.
"""

from __future__ import annotations

import math

import numpy as np

from sandbox.msgs.geometry_msgs import Point, Pose, Twist, Vector3
from sandbox.msgs.nav_msgs import Odometry
from sandbox.msgs.std_msgs import Int32MultiArray
from server.sim.kinematics import wrap_angle
from server.sim.sensors.base import SenseContext, StatelessSensor
from server.sim.sensors.frames import diagonal_covariance, stamped_header, yaw_orientation

# Defaults
# | name                    | value  | unit   | why                                              |
# |-------------------------|--------|--------|--------------------------------------------------|
_RATE_HZ = 20.0  # [Hz]                 sensor-stream polling by the driver (assumption)
_WHEEL_RADIUS_M = 0.036  # [m]          Create OI spec: 72 mm wheel diameter
_TRACK_M = 0.235  # [m]                 Create OI spec: distance between the wheels
_UNOBSERVABLE_VAR = 1e6  # [-]          z, roll, pitch: a planar base cannot tell
# Pose (x, y, z, roll, pitch, yaw) [m^2, rad^2] and twist [(m/s)^2, (rad/s)^2] variances.
_POSE_VARIANCES = (1e-3, 1e-3, _UNOBSERVABLE_VAR, _UNOBSERVABLE_VAR, _UNOBSERVABLE_VAR, 1e-2)
_TWIST_VARIANCES = (1e-4, 1e-6, _UNOBSERVABLE_VAR, _UNOBSERVABLE_VAR, _UNOBSERVABLE_VAR, 1e-3)
_BOTH_BUMPERS_RAD = math.radians(10.0)  # [rad] a head-on contact presses both switches
_BUMPER_SIDE_RAD = math.radians(90.0)  # [rad]  the bumper covers the front half


class WheelOdometry(StatelessSensor):
    """The base's wheel odometry as nav_msgs/Odometry (see module doc)."""

    msg_type = Odometry

    def __init__(
        self,
        *,
        rate_hz: float = _RATE_HZ,
        wheel_radius_m: float = _WHEEL_RADIUS_M,
        track_m: float = _TRACK_M,
        frame_id: str = "odom",
        child_frame_id: str = "base_link",
        pose_variances: tuple[float, ...] = _POSE_VARIANCES,
        twist_variances: tuple[float, ...] = _TWIST_VARIANCES,
    ) -> None:
        """`pose_variances`/`twist_variances`: the six diagonal entries (x, y, z, roll, pitch,
        yaw) the driver fills in; all zeros where the real firmware leaves them unset."""
        if len(pose_variances) != 6 or len(twist_variances) != 6:
            raise ValueError("WheelOdometry needs six pose and six twist variances")
        if wheel_radius_m <= 0.0 or track_m <= 0.0:
            raise ValueError(
                f"WheelOdometry needs wheel_radius_m > 0 and track_m > 0, "
                f"got {wheel_radius_m} and {track_m}."
            )
        self.rate_hz = float(rate_hz)
        self.wheel_radius_m = float(wheel_radius_m)
        self.track_m = float(track_m)
        self.frame_id = frame_id
        self.child_frame_id = child_frame_id
        self.pose_covariance = diagonal_covariance(pose_variances)
        self.twist_covariance = diagonal_covariance(twist_variances)

    def sample(self, ctx: SenseContext, rng: np.random.Generator) -> Odometry:
        state = ctx.state
        odom_pose = state.odometry_pose
        left_m_s = self.wheel_radius_m * state.wheel_left_rad_s
        right_m_s = self.wheel_radius_m * state.wheel_right_rad_s
        odometry = Odometry(
            header=stamped_header(ctx.time_s, self.frame_id), child_frame_id=self.child_frame_id
        )
        odometry.pose.pose = Pose(
            position=Point(x=odom_pose.x, y=odom_pose.y, z=0.0),
            orientation=yaw_orientation(odom_pose.yaw),
        )
        odometry.pose.covariance = list(self.pose_covariance)
        odometry.twist.twist = Twist(
            linear=Vector3(x=0.5 * (left_m_s + right_m_s), y=0.0, z=0.0),
            angular=Vector3(x=0.0, y=0.0, z=(right_m_s - left_m_s) / self.track_m),
        )
        odometry.twist.covariance = list(self.twist_covariance)
        return odometry


class Bumper(StatelessSensor):
    """The base's left/right bump switches as std_msgs/Int32MultiArray [left, right]."""

    msg_type = Int32MultiArray

    def __init__(
        self,
        *,
        rate_hz: float = _RATE_HZ,
        both_within_rad: float = _BOTH_BUMPERS_RAD,
        side_limit_rad: float = _BUMPER_SIDE_RAD,
    ) -> None:
        self.rate_hz = float(rate_hz)
        self.both_within_rad = float(both_within_rad)
        self.side_limit_rad = float(side_limit_rad)

    def pressed(self, contact_angles_rad: tuple[float, ...]) -> tuple[int, int]:
        """(left, right), 1 = pressed, for contacts at these robot-frame angles [rad]."""
        angles = np.array([wrap_angle(float(a)) for a in contact_angles_rad], dtype=np.float64)
        head_on = np.abs(angles) < self.both_within_rad
        left = (angles > 0.0) & (angles <= self.side_limit_rad)
        right = (angles <= 0.0) & (angles >= -self.side_limit_rad)
        return int(np.any(left | head_on)), int(np.any(right | head_on))

    def sample(self, ctx: SenseContext, rng: np.random.Generator) -> Int32MultiArray:
        return Int32MultiArray(data=list(self.pressed(ctx.state.contact_angles_rad)))
