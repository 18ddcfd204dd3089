"""Motor models: what the wheels actually do with a velocity command.

Two models, both with a first-order lag (a DC motor with its gearbox and the robot's mass do not
change speed instantly):

- `CrowBotFirmwareMotors` follows the CrowBot BOLT firmware path exactly (shared/seeds/README.md,
  000_32b6074bbd2115c3.txt eq. 1-2 and Table 2): Twist -> wheel speeds [rad/s] -> x K -> truncated
  to int -> clamped to the 8-bit PWM range (the sign picks the motor pin) -> wheel speed. A PWM
  duty below the dead band does not overcome the gearbox's static friction and leaves the wheel
  still. So a command the real robot cannot follow (faster than PWM 255 allows, or too slow to
  start the motor) is not followed in simulation either.
- `VelocityMotors` models a base with its own speed controller (the Roomba's Drive Direct, the
  rover's and the miniQ's H-bridges): per-wheel speed limit, acceleration limit and lag.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

from server.sim.kinematics import wheel_speeds

# CrowBot firmware constants (000 Table 2, firmware in shared/seeds/README.md).
CROWBOT_WHEEL_RADIUS_M = 0.02  # [m] r; D = 0.04 m in Table 2
CROWBOT_TRACK_M = 0.08  # [m] d, wheel separation
CROWBOT_PWM_PER_RAD_S = 40.0  # [PWM counts per rad/s] K, tuned empirically in the paper
CROWBOT_PWM_MAX = 255  # [counts] 8-bit PWM (ESP32 ledc, 8-bit resolution)
# Assumption (not in the paper): duty below ~8% does not start the small geared motors.
CROWBOT_PWM_DEAD_BAND = 20  # [counts]
# Assumption: a small geared motor carrying a 0.2 kg robot reaches 63% of a step in ~50 ms.
CROWBOT_MOTOR_TIME_CONSTANT_S = 0.05  # [s]


@functools.lru_cache(maxsize=64)
def _lag_factor(dt_s: float, time_constant_s: float) -> float:
    """exp(-dt / tau): the part of the old error a first-order lag keeps after `dt_s`. Cached
    because the physics tick is fixed, and exp() is a measurable part of a 20 kHz step."""
    if time_constant_s <= 0.0:
        return 0.0
    return math.exp(-dt_s / time_constant_s)


def _lag(current: float, target: float, dt_s: float, time_constant_s: float) -> float:
    """Exact first-order lag step toward `target`."""
    return target + (current - target) * _lag_factor(dt_s, time_constant_s)


def crowbot_pwm(wheel_rad_s: float) -> int:
    """The firmware's duty for one wheel: x K, truncated to int (C cast), clamped to +-255."""
    duty = int(wheel_rad_s * CROWBOT_PWM_PER_RAD_S)  # int() truncates toward zero, as C does
    return max(-CROWBOT_PWM_MAX, min(CROWBOT_PWM_MAX, duty))


@dataclass(slots=True)
class CrowBotFirmwareMotors:
    """The CrowBot's Twist-to-PWM firmware path with a dead band and a first-order lag."""

    wheel_radius_m: float = CROWBOT_WHEEL_RADIUS_M
    track_m: float = CROWBOT_TRACK_M
    dead_band_pwm: int = CROWBOT_PWM_DEAD_BAND
    time_constant_s: float = CROWBOT_MOTOR_TIME_CONSTANT_S
    left_pwm: int = 0
    right_pwm: int = 0
    left_rad_s: float = 0.0
    right_rad_s: float = 0.0

    def reset(self) -> None:
        self.left_pwm = self.right_pwm = 0
        self.left_rad_s = self.right_rad_s = 0.0

    def command(self, linear_m_s: float, angular_rad_s: float) -> None:
        """Set the PWM duties the firmware would write for this Twist."""
        left, right = wheel_speeds(linear_m_s, angular_rad_s, self.wheel_radius_m, self.track_m)
        self.left_pwm = crowbot_pwm(left)
        self.right_pwm = crowbot_pwm(right)

    def _duty_to_speed(self, pwm: int) -> float:
        if abs(pwm) < self.dead_band_pwm:
            return 0.0
        return pwm / CROWBOT_PWM_PER_RAD_S

    def step(self, dt_s: float) -> tuple[float, float]:
        """Advance the wheels by `dt_s`; returns (left, right) wheel speeds [rad/s]."""
        self.left_rad_s = _lag(
            self.left_rad_s, self._duty_to_speed(self.left_pwm), dt_s, self.time_constant_s
        )
        self.right_rad_s = _lag(
            self.right_rad_s, self._duty_to_speed(self.right_pwm), dt_s, self.time_constant_s
        )
        return self.left_rad_s, self.right_rad_s


@dataclass(slots=True)
class VelocityMotors:
    """A base with its own wheel speed controller: clamp, acceleration limit, first-order lag.

    Each wheel is clamped on its own (as the Roomba's Drive Direct does), so an over-fast turn
    command changes the curvature the robot actually drives, like the real base.
    """

    wheel_radius_m: float
    track_m: float
    max_wheel_rad_s: float
    max_wheel_accel_rad_s2: float
    time_constant_s: float
    target_left_rad_s: float = 0.0
    target_right_rad_s: float = 0.0
    left_rad_s: float = 0.0
    right_rad_s: float = 0.0

    def reset(self) -> None:
        self.target_left_rad_s = self.target_right_rad_s = 0.0
        self.left_rad_s = self.right_rad_s = 0.0

    def command(self, linear_m_s: float, angular_rad_s: float) -> None:
        left, right = wheel_speeds(linear_m_s, angular_rad_s, self.wheel_radius_m, self.track_m)
        limit = self.max_wheel_rad_s
        self.target_left_rad_s = max(-limit, min(limit, left))
        self.target_right_rad_s = max(-limit, min(limit, right))

    def _advance(self, current: float, target: float, dt_s: float) -> float:
        lagged = _lag(current, target, dt_s, self.time_constant_s)
        max_change = self.max_wheel_accel_rad_s2 * dt_s
        return current + max(-max_change, min(max_change, lagged - current))

    def step(self, dt_s: float) -> tuple[float, float]:
        self.left_rad_s = self._advance(self.left_rad_s, self.target_left_rad_s, dt_s)
        self.right_rad_s = self._advance(self.right_rad_s, self.target_right_rad_s, dt_s)
        return self.left_rad_s, self.right_rad_s
