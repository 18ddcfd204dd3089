"""Differential-drive kinematics of the Create/Roomba base: body velocity to Drive Direct wheel
speeds, and wheel encoder counts to odometry. Pure math, SI units, REP 103 frames (x forward,
y left, yaw counter-clockwise).

Sources:
- iRobot Roomba 500 / Create 2 Open Interface specifications, packets 43/44: 508.8 encoder
  counts per wheel revolution, 72 mm wheel diameter, 235 mm between the wheels; the counters
  roll over at 16 bits. (server/sim/robots/turtlebot.py uses the same 0.036 m and 0.235 m.)
- 003_4f92d1fa0a49ddae.txt section 2.1, eq. 2.7: the differential-drive map between wheel and
  body velocities, v = (v_l + v_r) / 2 and omega = (v_r - v_l) / b with the track b (written
  here with REP 103's sign, the right wheel faster turns left).
- Dead reckoning over one sample integrates that motion along a circular arc (exact for
  constant wheel speeds within the sample), as libcreate's Create::onData does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

WHEEL_BASE_M = 0.235  # [m] distance between the wheels, OI spec
WHEEL_DIAMETER_M = 0.072  # [m] OI spec
COUNTS_PER_REV = 508.8  # [counts/rev] OI spec, packets 43/44
METERS_PER_COUNT = math.pi * WHEEL_DIAMETER_M / COUNTS_PER_REV  # [m/count] ~0.445 mm
MAX_WHEEL_M_S = 0.5  # [m/s] Drive Direct accepts -500..500 mm/s per wheel
ENCODER_MODULUS = 1 << 16  # [counts] the counters are 16-bit registers
_STRAIGHT_EPS_RAD = 1e-9  # [rad] below this heading change, integrate a straight line


@dataclass(frozen=True)
class WheelSpeeds:
    """Tangential wheel speeds [m/s], as Drive Direct takes them (it wants mm/s)."""

    left_m_s: float
    right_m_s: float


def twist_to_wheel_speeds(
    linear_m_s: float,
    angular_rad_s: float,
    *,
    wheel_base_m: float = WHEEL_BASE_M,
    max_wheel_m_s: float = MAX_WHEEL_M_S,
) -> WheelSpeeds:
    """Body velocity -> wheel speeds (eq. 2.7 inverted). A command past the wheel limit is scaled
    down as a whole, so the robot still drives the commanded curve, only slower; clamping each
    wheel on its own would change the curvature (a fast arc would become a straight line)."""
    if not (math.isfinite(linear_m_s) and math.isfinite(angular_rad_s)):
        raise ValueError(
            f"a velocity command needs finite numbers, got linear {linear_m_s} m/s and "
            f"angular {angular_rad_s} rad/s"
        )
    half_track_m_s = 0.5 * wheel_base_m * angular_rad_s
    left = linear_m_s - half_track_m_s
    right = linear_m_s + half_track_m_s
    fastest = max(abs(left), abs(right))
    if fastest > max_wheel_m_s:
        scale = max_wheel_m_s / fastest
        left, right = left * scale, right * scale
    return WheelSpeeds(left_m_s=left, right_m_s=right)


def encoder_delta(previous_counts: int, current_counts: int) -> int:
    """Signed counts from `previous_counts` to `current_counts` of a 16-bit counter: the shorter
    way round, so 65530 -> 4 is +10 and 4 -> 65530 is -10. Right while a wheel moves less than
    half the register (32768 counts, ~14.6 m) between two reads; at 0.5 m/s and 15 ms frames it
    moves ~17 counts."""
    return (current_counts - previous_counts + ENCODER_MODULUS // 2) % ENCODER_MODULUS - (
        ENCODER_MODULUS // 2
    )


@dataclass(frozen=True)
class Pose2D:
    """A planar pose in the odom frame: x, y [m], yaw [rad] wrapped to (-pi, pi]."""

    x_m: float = 0.0
    y_m: float = 0.0
    yaw_rad: float = 0.0


@dataclass(frozen=True)
class OdometryStep:
    """What one encoder sample moved: each wheel [m], and the body's path length [m] and
    heading change [rad] (counter-clockwise +)."""

    left_m: float
    right_m: float
    distance_m: float
    yaw_change_rad: float


def wrap_angle(angle_rad: float) -> float:
    """`angle_rad` wrapped to (-pi, pi]."""
    wrapped = math.remainder(angle_rad, 2.0 * math.pi)
    return math.pi if wrapped == -math.pi else wrapped


def wheel_travel_to_step(left_m: float, right_m: float, wheel_base_m: float) -> OdometryStep:
    """Wheel travel [m] -> body distance and heading change (eq. 2.7 over one sample)."""
    return OdometryStep(
        left_m=left_m,
        right_m=right_m,
        distance_m=0.5 * (left_m + right_m),
        yaw_change_rad=(right_m - left_m) / wheel_base_m,
    )


def advance_pose(pose: Pose2D, distance_m: float, yaw_change_rad: float) -> Pose2D:
    """`pose` moved `distance_m` along an arc that turns by `yaw_change_rad`."""
    if abs(yaw_change_rad) < _STRAIGHT_EPS_RAD:
        dx = distance_m * math.cos(pose.yaw_rad)
        dy = distance_m * math.sin(pose.yaw_rad)
    else:
        radius_m = distance_m / yaw_change_rad
        new_yaw = pose.yaw_rad + yaw_change_rad
        dx = radius_m * (math.sin(new_yaw) - math.sin(pose.yaw_rad))
        dy = -radius_m * (math.cos(new_yaw) - math.cos(pose.yaw_rad))
    return Pose2D(
        x_m=pose.x_m + dx,
        y_m=pose.y_m + dy,
        yaw_rad=wrap_angle(pose.yaw_rad + yaw_change_rad),
    )


class EncoderOdometry:
    """Dead reckoning from the two cumulative encoder counters (packets 43/44).

    The first sample only sets the reference: the counters hold whatever the robot counted since
    power-on, so the pose starts at the origin wherever the robot stands.
    """

    def __init__(
        self,
        *,
        meters_per_count: float = METERS_PER_COUNT,
        wheel_base_m: float = WHEEL_BASE_M,
    ) -> None:
        if meters_per_count <= 0.0 or wheel_base_m <= 0.0:
            raise ValueError(
                f"EncoderOdometry needs meters_per_count > 0 and wheel_base_m > 0, got "
                f"{meters_per_count} and {wheel_base_m}"
            )
        self.meters_per_count = float(meters_per_count)
        self.wheel_base_m = float(wheel_base_m)
        self.pose = Pose2D()
        self._last_counts: tuple[int, int] | None = None

    @property
    def started(self) -> bool:
        """Whether a first sample has set the reference counts."""
        return self._last_counts is not None

    def update(self, left_counts: int, right_counts: int) -> OdometryStep:
        """Take the counters' current values; return this sample's motion (zero for the first)
        and advance `pose`."""
        if self._last_counts is None:
            self._last_counts = (left_counts, right_counts)
            return OdometryStep(0.0, 0.0, 0.0, 0.0)
        last_left, last_right = self._last_counts
        self._last_counts = (left_counts, right_counts)
        step = wheel_travel_to_step(
            encoder_delta(last_left, left_counts) * self.meters_per_count,
            encoder_delta(last_right, right_counts) * self.meters_per_count,
            self.wheel_base_m,
        )
        self.pose = advance_pose(self.pose, step.distance_m, step.yaw_change_rad)
        return step
