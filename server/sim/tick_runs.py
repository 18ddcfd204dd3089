"""Runs of physics ticks evaluated as arrays: the same 1 kHz ticks, fewer Python steps.

Why (issue 18): a 60 s run is 60,000 ticks, and one tick in Python costs ~4 us, most of a
lockstep run's server time. Between two events (a command, a sensor sample, a node's wake-up)
nothing outside the robot changes, so the ticks of that stretch can be computed at once.

Why ticks and not single arcs: the kinematics are exact arcs for constant wheel speeds (003
eq. 2.1), but the motors lag their commands (a first-order lag, tau 40-80 ms, and an
acceleration limit), so the wheel speeds change every tick after a command and the path is a
chain of short arcs, not one. Replacing the chain by the continuous solution would move a pose
by ~0.5 ms x the speed change (~5e-5 m) per command. Instead a run of ticks evaluates exactly
the chain the 1 kHz loop builds: wheel speeds after each tick (each motor model's closed-form
`step_many`), then each tick's arc from those speeds (vectorized `integrate_arc`). The result
equals tick-by-tick stepping within float rounding (~1e-12 m after a minute), so sensor
readings, recordings and grading numbers stay those of the 1 kHz physics.

A run only covers ticks where nothing but motion happens: the body keeps a positive clearance
from every obstacle (the conservative advancement of `Simulation._resolve_contacts`, whose
clearance is used up by the same chord lengths here), and the robot stays inside the world's
bounds. The tick where either stops holding, and contact itself, go through the one-tick path,
so a collision is found on the same tick as before.

Pure numpy, no state: the caller (server/sim/simulation.py) commits what it accepts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from server.sim.kinematics import body_velocities, wrap_angle
from server.sim.state import Pose2D, RobotState

# Below this many ticks the array set-up (~30 us) costs more than stepping one by one (~4 us
# a tick); measured with bench/bench_sim.py.
MIN_TICKS_FOR_A_RUN = 8
# [rad] below this half-turn per tick, sin(x)/x is its Taylor series to x^4: the next term,
# x^6/5040, is under 3e-18 (float64 rounding is 1.1e-16). A 1 kHz tick turns < 5e-3 rad for
# every robot here (the fastest turns 3.2 rad/s).
_SINC_SERIES_BELOW_RAD = 5e-3


@dataclass(frozen=True, slots=True)
class ArcSteps:
    """Each tick's arc of one or more chains (rows): its displacement dx, dy [m], its signed
    chord length [m] (negative when reversing) and the heading after it [rad] (not wrapped:
    the start heading plus the turns so far)."""

    dx: np.ndarray
    dy: np.ndarray
    chord: np.ndarray
    yaw_after: np.ndarray


def sin_over_x(x: np.ndarray) -> np.ndarray:
    """sin(x) / x elementwise, 1 at 0."""
    if np.abs(x).max(initial=0.0) < _SINC_SERIES_BELOW_RAD:
        x2 = x * x
        return 1.0 - x2 * (1.0 / 6.0 - x2 * (1.0 / 120.0))
    safe = np.where(x == 0.0, 1.0, x)
    return np.where(x == 0.0, 1.0, np.sin(x) / safe)


def sin_over_x_scalar(x: float) -> float:
    """sin(x) / x for one float, 1 at 0."""
    if abs(x) < _SINC_SERIES_BELOW_RAD:
        x2 = x * x
        return 1.0 - x2 * (1.0 / 6.0 - x2 * (1.0 / 120.0))
    return math.sin(x) / x


def steady_arc(
    x: float, y: float, yaw: float, linear_m_s: float, angular_rad_s: float, duration_s: float
) -> tuple[float, float, float]:
    """`integrate_arc` over `duration_s` at constant speeds, in the chord form of `arc_steps`
    (no cancellation when the turn is tiny but not zero). Returns x, y [m] and the yaw [rad],
    not wrapped."""
    half = 0.5 * angular_rad_s * duration_s
    chord = linear_m_s * duration_s * sin_over_x_scalar(half)
    heading = yaw + half
    return x + chord * math.cos(heading), y + chord * math.sin(heading), yaw + 2.0 * half


def arc_steps(start_yaw: np.ndarray, travel_m: np.ndarray, turn_rad: np.ndarray) -> ArcSteps:
    """`integrate_arc` tick after tick for rows of chains at once (a pose and its odometry).

    `start_yaw` (rows,) [rad]; `travel_m` (rows, ticks) = linear speed x dt and `turn_rad` =
    angular speed x dt of each tick. An arc turning by t moves along the chord 2 R sin(t/2) =
    travel sin(t/2) / (t/2), heading at its middle: the arc of 003 eq. 2.1 written so that it
    needs no special case for a straight line (integrate_arc's two branches are its limits)."""
    half = 0.5 * turn_rad
    yaws = np.cumsum(np.concatenate((start_yaw[:, None], turn_rad), axis=1), axis=1)
    middle = yaws[:, :-1] + half
    chord = travel_m * sin_over_x(half)
    return ArcSteps(chord * np.cos(middle), chord * np.sin(middle), chord, yaws[:, 1:])


def ticks_within_clearance(moved_m: np.ndarray, clearance_m: float) -> int:
    """How many leading ticks keep the clearance positive once what they moved is used up (the
    one-tick path skips its distance query exactly while clearance - moved so far > 0)."""
    return int(np.searchsorted(np.cumsum(moved_m), clearance_m, side="left"))


def ticks_within_bounds(
    xs: np.ndarray, ys: np.ndarray, bounds: tuple[float, float, float, float]
) -> int:
    """How many leading points lie inside `bounds` (min_x, min_y, max_x, max_y) [m], edges
    included, as `World.in_bounds`."""
    min_x, min_y, max_x, max_y = bounds
    outside = (xs < min_x) | (xs > max_x) | (ys < min_y) | (ys > max_y)
    if not outside.any():
        return len(xs)
    return int(np.argmax(outside))


# ------------------------------------------------------------------------------- runs
@dataclass(frozen=True, slots=True)
class RunStart:
    """Where a run starts and what it must not cross: the true pose and the odometry pose
    (x, y [m], yaw [rad]), the clearance left [m] and the world's bounds (min_x, min_y, max_x,
    max_y) [m]; and the robot: wheel radius [m], track [m], each wheel's odometry scale, the
    body disc's offset ahead of the pose point [m], the tick [s]."""

    pose: tuple[float, float, float]
    odometry: tuple[float, float, float]
    clearance_m: float
    bounds: tuple[float, float, float, float]
    wheel_radius_m: float
    track_m: float
    odometry_scales: tuple[float, float]
    body_offset_m: float
    tick_s: float

    def bounds_margin_m(self) -> float:
        """Distance [m] from the pose point to the nearest edge of the bounds."""
        x, y, _ = self.pose
        min_x, min_y, max_x, max_y = self.bounds
        return min(x - min_x, max_x - x, y - min_y, max_y - y)


@dataclass(frozen=True, slots=True)
class RunPoint:
    """The robot k ticks into a run: poses (yaw not wrapped), wheel speeds [rad/s] after tick
    k, and since the run's start the distance the pose point moved [m] (sum of tick chords),
    the clearance the body used [m] and each wheel's turn [rad]."""

    pose: tuple[float, float, float]
    odometry: tuple[float, float, float]
    left_rad_s: float
    right_rad_s: float
    moved_m: float
    body_m: float
    left_turned_rad: float
    right_turned_rad: float


class ArrayRun:
    """A run whose wheel speeds change every tick (the motors' lag): each tick's arc as
    arrays. `ticks`: how many of the given ticks it covers before the body would use up its
    clearance or the pose point leave the bounds (those ticks go one by one)."""

    def __init__(self, start: RunStart, left: np.ndarray, right: np.ndarray) -> None:
        self.start = start
        scales = start.odometry_scales
        # Row 0: the true wheels; row 1: the same wheels as the miscalibrated odometry sees them.
        lefts = np.multiply.outer((1.0, scales[0]), left)
        rights = np.multiply.outer((1.0, scales[1]), right)
        travel_per_rad = start.wheel_radius_m * start.tick_s / 2.0
        turn_per_rad = start.wheel_radius_m * start.tick_s / start.track_m
        arcs = arc_steps(
            np.array((start.pose[2], start.odometry[2])),
            (rights + lefts) * travel_per_rad,
            (rights - lefts) * turn_per_rad,
        )
        moved = np.abs(arcs.chord[0])
        body = moved
        offset = start.body_offset_m
        if offset:  # the body disc sits ahead of the pose point and sweeps wider when turning
            after = arcs.yaw_after[0]
            before = np.concatenate(((start.pose[2],), after[:-1]))
            body = np.hypot(
                arcs.dx[0] + offset * (np.cos(after) - np.cos(before)),
                arcs.dy[0] + offset * (np.sin(after) - np.sin(before)),
            )
        self._x = np.cumsum(arcs.dx, axis=1)
        self._y = np.cumsum(arcs.dy, axis=1)
        self._yaw = arcs.yaw_after
        self._moved = np.cumsum(moved)
        self._body = np.cumsum(body) if offset else self._moved
        self._left, self._right = left, right
        self._left_turned, self._right_turned = np.cumsum(left), np.cumsum(right)
        ticks = len(left)
        if self._body[-1] >= start.clearance_m:
            ticks = int(np.searchsorted(self._body, start.clearance_m, side="left"))
        if self._moved[-1] >= start.bounds_margin_m():
            x, y, _ = start.pose
            ticks = min(ticks, ticks_within_bounds(x + self._x[0], y + self._y[0], start.bounds))
        self.ticks = ticks

    def point(self, k: int) -> RunPoint:
        start = self.start
        if k == 0:
            return RunPoint(start.pose, start.odometry, math.nan, math.nan, 0.0, 0.0, 0.0, 0.0)
        i = k - 1
        x, y, _ = start.pose
        odom_x, odom_y, _ = start.odometry
        dt = start.tick_s
        return RunPoint(
            (x + float(self._x[0, i]), y + float(self._y[0, i]), float(self._yaw[0, i])),
            (odom_x + float(self._x[1, i]), odom_y + float(self._y[1, i]), float(self._yaw[1, i])),
            float(self._left[i]),
            float(self._right[i]),
            float(self._moved[i]),
            float(self._body[i]),
            float(self._left_turned[i]) * dt,
            float(self._right_turned[i]) * dt,
        )


class SteadyRun:
    """A run at constant wheel speeds (settled, or still): every tick is the same arc, so any
    point of it is one arc from the start (003 eq. 2.1), and each tick moves the same chord.
    `ticks` as ArrayRun's; `crosses_bounds`: the run might leave the bounds (then take the
    array path, which finds the tick)."""

    def __init__(self, start: RunStart, left: float, right: float, ticks: int) -> None:
        self.start = start
        self.left, self.right = left, right
        radius, track, dt = start.wheel_radius_m, start.track_m, start.tick_s
        self._linear = radius * (right + left) / 2.0
        self._angular = radius * (right - left) / track
        odom_left, odom_right = left * start.odometry_scales[0], right * start.odometry_scales[1]
        self._odom_linear = radius * (odom_right + odom_left) / 2.0
        self._odom_angular = radius * (odom_right - odom_left) / track
        # Every point of a body moving at constant speeds runs on a circle at constant speed:
        # the pose point at `linear`, the body disc's centre at hypot(linear, angular x offset).
        arc_factor = dt * abs(sin_over_x_scalar(0.5 * self._angular * dt))
        self._chord = abs(self._linear) * arc_factor
        self._body = math.hypot(self._linear, self._angular * start.body_offset_m) * arc_factor
        if self._body > 0.0 and ticks * self._body >= start.clearance_m:
            # The ticks k = 1, 2, ... whose k x body stays under the clearance.
            ticks = min(ticks, math.ceil(start.clearance_m / self._body) - 1)
        self.ticks = max(ticks, 0)
        self.crosses_bounds = self.ticks * self._chord >= start.bounds_margin_m()

    def point(self, k: int) -> RunPoint:
        start = self.start
        duration = k * start.tick_s
        return RunPoint(
            steady_arc(*start.pose, self._linear, self._angular, duration),
            steady_arc(*start.odometry, self._odom_linear, self._odom_angular, duration),
            self.left,
            self.right,
            k * self._chord,
            k * self._body,
            self.left * duration,
            self.right * duration,
        )


def plan_run(start: RunStart, motors: object, ticks: int) -> ArrayRun | SteadyRun:
    """The run of the next `ticks` ticks from `start` (its `ticks` may be fewer), with
    `motors` (a motor model with `step_many`, maybe `steady_speeds`) moved to its end."""
    steady_speeds = getattr(motors, "steady_speeds", None)
    speeds = steady_speeds() if steady_speeds is not None else None
    if speeds is not None:
        run = SteadyRun(start, *speeds, ticks)
        if not run.crosses_bounds:
            return run
    snapshot = motor_snapshot(motors)
    run = ArrayRun(start, *motors.step_many(start.tick_s, ticks))
    if run.ticks < ticks:  # the motors went ahead too far: to the end of the run
        restore_motors(motors, snapshot)
        if run.ticks >= MIN_TICKS_FOR_A_RUN:
            motors.step_many(start.tick_s, run.ticks)
    return run


def move_along(
    state: RobotState, before: RunPoint, after: RunPoint, wheel_radius_m: float, track_m: float
) -> None:
    """Set the robot's motion state from point `before` of a run to point `after`."""
    x, y, yaw = after.pose
    state.pose = Pose2D(x, y, wrap_angle(yaw))
    x, y, yaw = after.odometry
    state.odometry_pose = Pose2D(x, y, wrap_angle(yaw))
    left, right = after.left_rad_s, after.right_rad_s
    state.wheel_left_rad_s, state.wheel_right_rad_s = left, right
    state.linear_m_s, state.angular_rad_s = body_velocities(left, right, wheel_radius_m, track_m)
    state.distance_travelled_m += after.moved_m - before.moved_m
    state.wheel_left_travel_rad += after.left_turned_rad - before.left_turned_rad
    state.wheel_right_travel_rad += after.right_turned_rad - before.right_turned_rad


def motor_snapshot(motors: object) -> tuple:
    """The fields of a motor model (a dataclass, maybe holding another), to put back when a
    run is cut short after its motors went ahead."""
    return tuple(
        (name, motor_snapshot(value) if hasattr(value, "__dataclass_fields__") else value)
        for name in motors.__dataclass_fields__
        for value in (getattr(motors, name),)
    )


def restore_motors(motors: object, snapshot: tuple) -> None:
    for name, value in snapshot:
        if isinstance(value, tuple) and hasattr(getattr(motors, name), "__dataclass_fields__"):
            restore_motors(getattr(motors, name), value)
        else:
            setattr(motors, name, value)
