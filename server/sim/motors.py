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
- `OpenCrMotors` follows the TurtleBot3's OpenCR firmware (ROBOTIS-GIT/OpenCR, noetic-devel,
  libraries/turtlebot3: turtlebot3_core.ino and turtlebot3_motor_driver.cpp): every 1/30 s it
  writes each Dynamixel a goal velocity in its integer units (0.229 rpm), truncated and clamped
  to +-265 units (61 rpm); a command older than 0.5 s is replaced by zero (the firmware's
  cmd_vel watchdog, CONTROL_MOTOR_TIMEOUT). The wheels then follow with `VelocityMotors`' lag.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

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


# [rad/s] A wheel this close to its target has settled (`steady_speeds`): what is left of its
# lag would move the robot by about wheel radius x time constant x this, ~1e-12 m, which is
# float rounding on a pose.
SETTLED_RAD_S = 1e-9


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


# One table of powers per lag factor (a robot's motors share one), as long as the longest tick
# run asked for so far (doubling): a run of n ticks reads the table's first n. An lru_cache keyed
# by (factor, ticks) held an array per distinct tick count instead, and a realtime run asks for
# whatever count the wall clock gives: up to 256 arrays of up to ~200 KB each (1.3 MiB in one
# worker process after 10 minutes of runs, `bench_cluster.py --tracemalloc`), bounded in number
# only. factor**k is computed element by element, so a prefix of a longer table is the same.
_POWER_TABLES: dict[float, np.ndarray] = {}
MAX_POWER_TABLES = 64  # distinct lag factors kept (one per motor model and physics tick)


def _lag_powers(factor: float, ticks: int) -> np.ndarray:
    """factor**1 .. factor**ticks, read-only: the part of the old error left after each tick."""
    table = _POWER_TABLES.get(factor)
    if table is None or len(table) < ticks:
        length = max(ticks, 2 * len(table)) if table is not None else ticks
        table = factor ** np.arange(1, length + 1, dtype=np.float64)
        table.flags.writeable = False
        if len(_POWER_TABLES) >= MAX_POWER_TABLES:
            _POWER_TABLES.clear()
        _POWER_TABLES[factor] = table  # threads racing here each keep a correct table
    return table[:ticks]


def _lag_many(current: float, target: float, ticks: int, factor: float) -> np.ndarray:
    """The speeds after each of `ticks` exact lag steps (`_lag` applied `ticks` times, in
    closed form; equal to the repeated steps within float rounding)."""
    return target + (current - target) * _lag_powers(factor, ticks)


def _ramp_then_lag(
    current: float, target: float, ticks: int, factor: float, max_change: float
) -> np.ndarray:
    """`VelocityMotors._advance` applied `ticks` times, in closed form. While the lag would
    change the speed by more than `max_change` in one tick, the speed ramps by exactly that
    much (a straight line); once it would not, it never will again (the gap only shrinks), and
    the rest is the plain lag."""
    gap = abs(target - current)
    # Nothing to follow, no acceleration allowed, or a lag that never moves (tau >> dt).
    if gap == 0.0 or max_change <= 0.0 or factor >= 1.0:
        return np.full(ticks, current)
    # Tick k (from 1) is clamped while gap - (k - 1) * max_change > max_change / (1 - factor).
    ramp_ticks = max(0, math.ceil(gap / max_change - 1.0 / (1.0 - factor)))
    ramp_ticks = min(ramp_ticks, ticks)
    if ramp_ticks == 0:
        return _lag_many(current, target, ticks, factor)
    step = math.copysign(max_change, target - current)
    ramp = current + step * np.arange(1, ramp_ticks + 1, dtype=np.float64)
    if ramp_ticks == ticks:
        return ramp
    rest = _lag_many(float(ramp[-1]), target, ticks - ramp_ticks, factor)
    return np.concatenate((ramp, rest))


def _settle(motors, left: float, right: float) -> tuple[float, float] | None:
    """(left, right) [rad/s] when both of `motors`' wheels are within SETTLED_RAD_S of these
    speeds, which they are then set to exactly (they stay until the next command); else None."""
    if (
        abs(motors.left_rad_s - left) < SETTLED_RAD_S
        and abs(motors.right_rad_s - right) < SETTLED_RAD_S
    ):
        motors.left_rad_s, motors.right_rad_s = left, right
        return left, right
    return None


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

    def steady_speeds(self) -> tuple[float, float] | None:
        """(left, right) [rad/s] when both wheels have settled on their speeds (set to them
        exactly: they stay until the next command), else None."""
        return _settle(
            self, self._duty_to_speed(self.left_pwm), self._duty_to_speed(self.right_pwm)
        )

    def step_many(self, dt_s: float, ticks: int) -> tuple[np.ndarray, np.ndarray]:
        """`step(dt_s)` `ticks` times at once: (left, right) wheel speeds [rad/s] after each."""
        factor = _lag_factor(dt_s, self.time_constant_s)
        left = _lag_many(self.left_rad_s, self._duty_to_speed(self.left_pwm), ticks, factor)
        right = _lag_many(self.right_rad_s, self._duty_to_speed(self.right_pwm), ticks, factor)
        self.left_rad_s, self.right_rad_s = float(left[-1]), float(right[-1])
        return left, right


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

    def steady_speeds(self) -> tuple[float, float] | None:
        """(left, right) [rad/s] when both wheels have settled on their targets (set to them
        exactly: they stay until the next command), else None."""
        return _settle(self, self.target_left_rad_s, self.target_right_rad_s)

    def step_many(self, dt_s: float, ticks: int) -> tuple[np.ndarray, np.ndarray]:
        """`step(dt_s)` `ticks` times at once: (left, right) wheel speeds [rad/s] after each."""
        factor = _lag_factor(dt_s, self.time_constant_s)
        max_change = self.max_wheel_accel_rad_s2 * dt_s
        left = _ramp_then_lag(self.left_rad_s, self.target_left_rad_s, ticks, factor, max_change)
        right = _ramp_then_lag(self.right_rad_s, self.target_right_rad_s, ticks, factor, max_change)
        self.left_rad_s, self.right_rad_s = float(left[-1]), float(right[-1])
        return left, right


# TurtleBot3 Burger firmware constants (OpenCR noetic-devel, turtlebot3_motor_driver.h and
# turtlebot3_core_config.h).
TB3_UNITS_PER_RAD_S = (
    41.69988758  # [units/(rad/s)] VELOCITY_CONSTANT_VALUE = 1/(0.229 rpm in rad/s)
)
TB3_BURGER_LIMIT_UNITS = 265  # [units] BURGER_DXL_LIMIT_MAX_VELOCITY: 61 rpm at 12 V
TB3_CONTROL_PERIOD_S = 1.0 / 30.0  # [s] CONTROL_MOTOR_SPEED_FREQUENCY, 30 Hz
TB3_COMMAND_TIMEOUT_S = 0.5  # [s] CONTROL_MOTOR_TIMEOUT: no cmd_vel for 500 ms stops the wheels


def dynamixel_units(wheel_rad_s: float, limit_units: int = TB3_BURGER_LIMIT_UNITS) -> int:
    """The goal velocity the firmware writes for one wheel: x units per rad/s, clamped to the
    limit, then cast to an integer (truncation toward zero, as the C cast does)."""
    units = max(-limit_units, min(limit_units, wheel_rad_s * TB3_UNITS_PER_RAD_S))
    return int(units)


@dataclass(slots=True)
class OpenCrMotors:
    """The TurtleBot3's OpenCR path from a (clamped) Twist to its two Dynamixels (module doc).

    `command()` is the cmd_vel callback: it stores the goal and restarts the watchdog. `step()`
    runs the firmware's 30 Hz control loop on simulated time and lags the wheels toward the
    goal written last. `timeout_s=None` turns the watchdog off."""

    wheel_radius_m: float
    track_m: float
    wheels: VelocityMotors
    limit_units: int = TB3_BURGER_LIMIT_UNITS
    control_period_s: float = TB3_CONTROL_PERIOD_S
    timeout_s: float | None = TB3_COMMAND_TIMEOUT_S
    goal_linear_m_s: float = 0.0
    goal_angular_rad_s: float = 0.0
    since_command_s: float = math.inf  # [s] nothing commanded yet: the wheels stay still
    since_control_s: float = 0.0
    left_units: int = 0
    right_units: int = 0

    def reset(self) -> None:
        self.wheels.reset()
        self.goal_linear_m_s = self.goal_angular_rad_s = 0.0
        self.since_command_s = math.inf
        self.since_control_s = 0.0
        self.left_units = self.right_units = 0

    def command(self, linear_m_s: float, angular_rad_s: float) -> None:
        self.goal_linear_m_s, self.goal_angular_rad_s = linear_m_s, angular_rad_s
        self.since_command_s = 0.0

    def _control(self) -> None:
        """One pass of the firmware's control loop: goal (or zero, if stale) to wheel units."""
        linear, angular = self.goal_linear_m_s, self.goal_angular_rad_s
        if self.timeout_s is not None and self.since_command_s > self.timeout_s:
            linear = angular = 0.0
        left, right = wheel_speeds(linear, angular, self.wheel_radius_m, self.track_m)
        self.left_units = dynamixel_units(left, self.limit_units)
        self.right_units = dynamixel_units(right, self.limit_units)
        self.wheels.target_left_rad_s = self.left_units / TB3_UNITS_PER_RAD_S
        self.wheels.target_right_rad_s = self.right_units / TB3_UNITS_PER_RAD_S

    def step(self, dt_s: float) -> tuple[float, float]:
        self.since_command_s += dt_s
        self.since_control_s += dt_s
        if self.since_control_s >= self.control_period_s - 1e-12:
            # A coarse physics tick may span several control passes: the last one wins.
            self.since_control_s = max(self.since_control_s - self.control_period_s, 0.0)
            self.since_control_s %= self.control_period_s
            self._control()
        return self.wheels.step(dt_s)

    def step_many(self, dt_s: float, ticks: int) -> tuple[np.ndarray, np.ndarray]:
        """`step(dt_s)` `ticks` times at once. The firmware's timers are kept tick by tick, as
        `step` keeps them (cheap, and the control passes land on the same ticks); the wheels
        follow each pass's goal in one closed-form run."""
        lefts, rights = [], []
        run_start = 0
        for tick in range(ticks):
            self.since_command_s += dt_s
            self.since_control_s += dt_s
            if self.since_control_s >= self.control_period_s - 1e-12:
                if tick > run_start:
                    left, right = self.wheels.step_many(dt_s, tick - run_start)
                    lefts.append(left)
                    rights.append(right)
                    run_start = tick
                self.since_control_s = max(self.since_control_s - self.control_period_s, 0.0)
                self.since_control_s %= self.control_period_s
                self._control()
        left, right = self.wheels.step_many(dt_s, ticks - run_start)
        if not lefts:
            return left, right
        return np.concatenate((*lefts, left)), np.concatenate((*rights, right))
