"""What the navigation server's controller does between two plans, without messages: the path's
geometry, Nav2's goal and progress checkers, and the built-in path follower.

- `path_length_from` / `closest_index`: Nav2's bt_navigator feedback (distance_remaining is the
  path's length from the pose closest to the robot; estimated_time_remaining that distance over
  the current speed when the robot moves faster than 1 cm/s and has more than 10 cm to go).
- `GoalChecker`: nav2_controller's SimpleGoalChecker (xy and yaw tolerances; stateful: once
  within the xy tolerance, only the yaw is checked until a new goal).
- `ProgressChecker`: nav2_controller's SimpleProgressChecker (the robot must move 0.5 m every
  10 s, or the goal fails).
- `PurePursuit`: a regulated pure pursuit follower after nav2_regulated_pure_pursuit_controller
  (Macenski et al., "Regulated Pure Pursuit for Robot Path Tracking", 2023): a carrot a fixed
  distance ahead on the path, curvature 2 y / L^2 to it, the speed lowered on tight curves and
  near the goal, rotation in place towards the path and, at the goal, to its heading.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# Defaults of the built-in follower: Nav2's RPP defaults except where the TurtleBot needs less.
FOLLOWER = {
    # [m/s] Nav2 says 0.5; the Roomba base tops out at 0.5 m/s per wheel, so a turn needs room
    "desired_linear_vel": 0.3,
    "lookahead_dist": 0.6,  # [m] carrot distance ahead of the robot
    "rotate_to_heading_angular_vel": 1.8,  # [rad/s] rotating in place
    "rotate_to_heading_min_angle": 0.785,  # [rad] a carrot further off than this: rotate first
    "max_angular_accel": 3.2,  # [rad/s^2] while rotating in place
    "regulated_linear_scaling_min_radius": 0.9,  # [m] tighter curves slow the robot down
    "regulated_linear_scaling_min_speed": 0.25,  # [m/s] ... but not below this
    "approach_velocity_scaling_dist": 0.6,  # [m] slow down over this last stretch of path
    "min_approach_linear_velocity": 0.05,  # [m/s] ... but not below this
}
XY_GOAL_TOLERANCE_M = 0.25  # [m] SimpleGoalChecker's default
YAW_GOAL_TOLERANCE_RAD = 0.25  # [rad] SimpleGoalChecker's default
PROGRESS_RADIUS_M = 0.5  # [m] SimpleProgressChecker's required_movement_radius
PROGRESS_TIME_S = 10.0  # [s] SimpleProgressChecker's movement_time_allowance
ETA_MIN_SPEED_M_S = 0.01  # [m/s] bt_navigator: slower than this, no time estimate
ETA_MIN_DISTANCE_M = 0.1  # [m] bt_navigator: closer than this, no time estimate


def wrap(angle_rad: float) -> float:
    """The angle in [-pi, pi)."""
    return (angle_rad + math.pi) % (2.0 * math.pi) - math.pi


def closest_index(points: np.ndarray, x: float, y: float) -> int:
    """Index of the path pose nearest to (x, y) (Nav2 looks at poses, not segments)."""
    return int(np.argmin(np.hypot(points[:, 0] - x, points[:, 1] - y)))


def path_length_from(points: np.ndarray, start: int) -> float:
    """Length [m] of the path from pose `start` to its end."""
    if start >= len(points) - 1:
        return 0.0
    return float(np.hypot(*np.diff(points[start:], axis=0).T).sum())


def estimated_time_s(distance_m: float, speed_m_s: float) -> float:
    """bt_navigator's estimate: distance over speed, 0 when slow or nearly there."""
    if abs(speed_m_s) > ETA_MIN_SPEED_M_S and distance_m > ETA_MIN_DISTANCE_M:
        return distance_m / abs(speed_m_s)
    return 0.0


@dataclass
class GoalChecker:
    xy_tolerance_m: float = XY_GOAL_TOLERANCE_M
    yaw_tolerance_rad: float = YAW_GOAL_TOLERANCE_RAD
    stateful: bool = True
    _check_xy: bool = True

    def reset(self) -> None:
        self._check_xy = True

    @property
    def xy_reached(self) -> bool:
        """Stateful: the robot has been within the xy tolerance of this goal."""
        return not self._check_xy

    def reached(self, pose: tuple[float, float, float], goal: tuple[float, float, float]) -> bool:
        if self._check_xy:
            if math.hypot(pose[0] - goal[0], pose[1] - goal[1]) > self.xy_tolerance_m:
                return False
            if self.stateful:
                self._check_xy = False
        return abs(wrap(goal[2] - pose[2])) <= self.yaw_tolerance_rad


@dataclass
class ProgressChecker:
    radius_m: float = PROGRESS_RADIUS_M
    time_allowance_s: float = PROGRESS_TIME_S
    _anchor: tuple[float, float, float] | None = None  # (x, y, time) of the last progress

    def reset(self) -> None:
        self._anchor = None

    def check(self, x: float, y: float, time_s: float) -> bool:
        """False once the robot has stayed within `radius_m` of one spot for too long."""
        anchor = self._anchor
        if anchor is None or math.hypot(x - anchor[0], y - anchor[1]) > self.radius_m:
            self._anchor = (x, y, time_s)
            return True
        return time_s - anchor[2] <= self.time_allowance_s


class PurePursuit:
    """The built-in controller: (v, w) for the robot at a pose, following `points` to `goal`."""

    def __init__(self, params: dict[str, float] | None = None) -> None:
        self.p = {**FOLLOWER, **(params or {})}
        self.last_w = 0.0

    def reset(self) -> None:
        self.last_w = 0.0

    def _rotate(self, angle_rad: float, period_s: float) -> tuple[float, float]:
        p = self.p
        target = math.copysign(p["rotate_to_heading_angular_vel"], angle_rad)
        step = p["max_angular_accel"] * period_s
        w = min(max(target, self.last_w - step), self.last_w + step)
        # never past the heading within one period
        if abs(w) * period_s > abs(angle_rad):
            w = angle_rad / period_s
        self.last_w = w
        return 0.0, w

    def command(
        self,
        pose: tuple[float, float, float],
        points: np.ndarray,
        goal_yaw: float,
        xy_reached: bool,
        period_s: float,
    ) -> tuple[float, float]:
        p = self.p
        x, y, yaw = pose
        if xy_reached or len(points) < 2:
            return self._rotate(wrap(goal_yaw - yaw), period_s)
        start = closest_index(points, x, y)
        distance = np.hypot(points[start:, 0] - x, points[start:, 1] - y)
        ahead = np.flatnonzero(distance >= p["lookahead_dist"])
        carrot = points[start + int(ahead[0])] if len(ahead) else points[-1]
        dx, dy = carrot[0] - x, carrot[1] - y
        forward = math.cos(yaw) * dx + math.sin(yaw) * dy
        left = -math.sin(yaw) * dx + math.cos(yaw) * dy
        angle = math.atan2(left, forward)
        if abs(angle) > p["rotate_to_heading_min_angle"]:
            return self._rotate(angle, period_s)
        curvature = 2.0 * left / max(forward * forward + left * left, 1e-9)
        v = p["desired_linear_vel"]
        if (
            abs(curvature) > 1e-9
            and 1.0 / abs(curvature) < p["regulated_linear_scaling_min_radius"]
        ):
            scaled = v / (abs(curvature) * p["regulated_linear_scaling_min_radius"])
            v = max(scaled, p["regulated_linear_scaling_min_speed"])
        remaining = path_length_from(points, start) + float(distance[0])
        if remaining < p["approach_velocity_scaling_dist"]:
            approach = v * remaining / p["approach_velocity_scaling_dist"]
            v = min(v, max(approach, p["min_approach_linear_velocity"]))
        self.last_w = v * curvature
        return v, self.last_w
