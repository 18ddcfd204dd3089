"""Differential-drive kinematics.

- The unicycle model of 003_4f92d1fa0a49ddae.txt eq. 2.1 (x' = v cos(yaw), y' = v sin(yaw),
  yaw' = w), integrated exactly over a step as a circular arc rather than with Euler steps, so a
  long step on a curve stays on the curve.
- Wheel-speed transforms of 000_32b6074bbd2115c3.txt eq. 1-2 (omega_1 = (2u + d w) / D for the
  right wheel, omega_2 = (2u - d w) / D for the left one; D = 2r the wheel diameter, d the wheel
  separation), the same relation as 003 eq. 2.7.

Pure functions of floats: no numpy, no state, cheap enough for the physics hot loop.
"""

from __future__ import annotations

import math

STRAIGHT_TURN_RAD = 1e-9  # [rad] |w dt| below this the arc is a straight line (avoid v/w blow-up)


def wrap_angle(angle_rad: float) -> float:
    """Wrap an angle to (-pi, pi]."""
    # Fast path: after one physics tick the angle is at most slightly outside the range.
    if -math.pi < angle_rad <= math.pi:
        return angle_rad
    wrapped = math.fmod(angle_rad + math.pi, 2.0 * math.pi)
    if wrapped <= 0.0:
        wrapped += 2.0 * math.pi
    return wrapped - math.pi


def integrate_arc(
    x: float, y: float, yaw: float, linear_m_s: float, angular_rad_s: float, dt_s: float
) -> tuple[float, float, float]:
    """Advance a pose by constant body velocities for `dt_s`, exactly (003 eq. 2.1).

    Returns the new (x [m], y [m], yaw [rad] wrapped to (-pi, pi]).
    """
    turn = angular_rad_s * dt_s
    if abs(turn) < STRAIGHT_TURN_RAD:
        # Midpoint heading keeps second-order accuracy for the tiny residual turn.
        heading = yaw + 0.5 * turn
        return (
            x + linear_m_s * dt_s * math.cos(heading),
            y + linear_m_s * dt_s * math.sin(heading),
            wrap_angle(yaw + turn),
        )
    radius = linear_m_s / angular_rad_s
    new_yaw = yaw + turn
    return (
        x + radius * (math.sin(new_yaw) - math.sin(yaw)),
        y - radius * (math.cos(new_yaw) - math.cos(yaw)),
        wrap_angle(new_yaw),
    )


def wheel_speeds(
    linear_m_s: float, angular_rad_s: float, wheel_radius_m: float, track_m: float
) -> tuple[float, float]:
    """Body velocities -> (left, right) wheel angular speeds [rad/s] (000 eq. 1-2)."""
    diameter = 2.0 * wheel_radius_m
    right = (2.0 * linear_m_s + track_m * angular_rad_s) / diameter
    left = (2.0 * linear_m_s - track_m * angular_rad_s) / diameter
    return left, right


def body_velocities(
    left_rad_s: float, right_rad_s: float, wheel_radius_m: float, track_m: float
) -> tuple[float, float]:
    """(left, right) wheel angular speeds [rad/s] -> (linear [m/s], angular [rad/s])."""
    linear = wheel_radius_m * (right_rad_s + left_rad_s) / 2.0
    angular = wheel_radius_m * (right_rad_s - left_rad_s) / track_m
    return linear, angular
