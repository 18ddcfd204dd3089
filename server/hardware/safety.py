"""What stands between a student's command and a real robot, and cannot be bypassed from the
sandbox: it runs in the server, after the command left the student's node.

- `VelocityLimiter`: the inventory entry's speed and acceleration limits, applied to every Twist
  (a student asking for 5 m/s gets the robot's limit; a step from 0 to full speed is ramped).
- `Watchdog`: a command older than `timeout_s` (500 ms by default, as ROS base drivers time out
  cmd_vel) is replaced by zero velocity; a crashed, killed or stuck node stops the robot.
- `ZERO`: what every end of a hardware run sends (run end, node crash, sandbox kill, server
  shutdown, lost connection), with the LEDs off.

Pure: the time is passed in, so the tests drive it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

DEFAULT_WATCHDOG_S = 0.5  # [s] no command for this long -> zero velocity
NOT_FINITE = "not_finite"  # a NaN or inf asked for: zero sent instead


@dataclass(frozen=True, slots=True)
class MotionLimits:
    """Per robot, from its inventory entry; each must be positive and finite."""

    max_linear_m_s: float  # [m/s]
    max_angular_rad_s: float  # [rad/s]
    max_linear_accel_m_s2: float  # [m/s^2]
    max_angular_accel_rad_s2: float  # [rad/s^2]

    def __post_init__(self) -> None:
        for name in self.__slots__:
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive number, got {value!r}")


@dataclass(frozen=True, slots=True)
class Velocity:
    linear_m_s: float = 0.0
    angular_rad_s: float = 0.0


ZERO = Velocity()


def _clamp(value: float, limit: float) -> float:
    if not math.isfinite(value):
        return 0.0  # a NaN or inf from a student's bug stops the robot, not spins it
    return max(-limit, min(limit, value))


def _ramp(current: float, target: float, max_step: float) -> float:
    """Toward `target` by at most `max_step`; exactly `target` once within reach (adding the
    difference back could land a rounding error past a limit: 0.30000000000000004 m/s)."""
    step = target - current
    if abs(step) <= max_step:
        return target
    return current + math.copysign(max_step, step)


class VelocityLimiter:
    """Clamp each command to the robot's speeds, and ramp it by the acceleration limits from the
    velocity last sent."""

    def __init__(self, limits: MotionLimits) -> None:
        self.limits = limits
        self.sent = ZERO
        self._sent_at_s: float | None = None
        self.clamped = 0  # commands that asked for more than the robot may do
        # The MotionLimits fields that changed the last command (NOT_FINITE for a NaN or inf),
        # in the order applied; empty when it went out as asked.
        self.limited_by: tuple[str, ...] = ()

    def apply(self, wanted: Velocity, now_s: float) -> Velocity:
        limits = self.limits
        linear = _clamp(wanted.linear_m_s, limits.max_linear_m_s)
        angular = _clamp(wanted.angular_rad_s, limits.max_angular_rad_s)
        changed = [
            NOT_FINITE if not math.isfinite(asked) else name
            for asked, got, name in (
                (wanted.linear_m_s, linear, "max_linear_m_s"),
                (wanted.angular_rad_s, angular, "max_angular_rad_s"),
            )
            if asked != got
        ]
        if changed:
            self.clamped += 1
        # The robot starts at rest: the first command ramps from zero too.
        dt = 0.0 if self._sent_at_s is None else max(0.0, now_s - self._sent_at_s)
        ramped_linear = _ramp(self.sent.linear_m_s, linear, limits.max_linear_accel_m_s2 * dt)
        ramped_angular = _ramp(
            self.sent.angular_rad_s, angular, limits.max_angular_accel_rad_s2 * dt
        )
        if ramped_linear != linear:
            changed.append("max_linear_accel_m_s2")
        if ramped_angular != angular:
            changed.append("max_angular_accel_rad_s2")
        linear, angular = ramped_linear, ramped_angular
        self.limited_by = tuple(dict.fromkeys(changed))
        self.sent = Velocity(linear, angular)
        self._sent_at_s = now_s
        return self.sent


class Watchdog:
    """Zero velocity when the newest command is older than `timeout_s`."""

    def __init__(self, timeout_s: float = DEFAULT_WATCHDOG_S) -> None:
        if not (math.isfinite(timeout_s) and timeout_s > 0):
            raise ValueError(f"the watchdog timeout must be a positive number, got {timeout_s!r}")
        self.timeout_s = timeout_s
        self._last_command_s: float | None = None
        self.trips = 0  # how often it had to stop the robot
        self._tripped = False

    def feed(self, now_s: float) -> None:
        self._last_command_s = now_s
        self._tripped = False

    def expired(self, now_s: float) -> bool:
        """True when the robot must be stopped now (counted once per silence)."""
        silent = self._last_command_s is None or now_s - self._last_command_s > self.timeout_s
        if silent and not self._tripped and self._last_command_s is not None:
            self.trips += 1
            self._tripped = True
        return silent
