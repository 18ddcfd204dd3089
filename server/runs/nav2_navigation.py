"""One NavigateToPose goal being carried out: its plan, its checkers, the commands and the
feedback, as Nav2's planner server, controller server and bt_navigator share the work.

- Plan: A* over the map grown by the robot's radius (server/runs/builtin.py, the `planner`
  built-in's search), from the localized pose to the goal, once per goal. The path's last pose
  is the goal itself; each pose faces the next (NavFn gives positions, the last pose the goal's
  orientation). Or, as the thesis plans for its Stanley controller, Hybrid A* (nav2_hybrid.py,
  like Nav2's SMAC Hybrid-A* planner): arcs of a minimum turning radius ending in the goal's
  heading. Nav2's default behaviour tree replans at 1 Hz; here the plan stays, as the
  ROS 1 exercise's planner does, so both dialects grade the same path.
- Control: each control period the goal checker, the progress checker, then a command: from the
  built-in follower (nav2_follow.PurePursuit) or, in the thesis's form (003_4f92d1fa0a49ddae.txt
  section 5.9), from a service a student node serves: the request carries the robot's pose and
  the path, the response the velocities; the server publishes them on cmd_vel.
- Feedback: bt_navigator's values (nav2_follow).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from server.runs.builtin import astar
from server.runs.nav2_follow import (
    GoalChecker,
    ProgressChecker,
    closest_index,
    estimated_time_s,
    path_length_from,
    wrap,
)
from server.runs.nav2_hybrid import SAMPLE_M, STEP_M, grid_distance, hybrid_astar

Pose = tuple[float, float, float]  # x [m], y [m], yaw [rad] in the map frame


class NoPath(Exception):
    """The planner found no way to the goal; the message says why, in a sentence, and `code`
    names ComputePathToPose's error code for it."""

    def __init__(self, message: str, code: str) -> None:
        super().__init__(message)
        self.code = code


def yaw_of(orientation: Any) -> float:
    """Yaw [rad] of a quaternion message (any roll and pitch ignored)."""
    q = orientation
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


PLANNERS = ("astar", "hybrid_astar")  # NavFn-like on the grid; SMAC Hybrid-A*-like


def plan_path(
    planner: Any, start: Pose, goal: Pose, kind: str = "astar", radius_m: float = 0.4
) -> tuple[np.ndarray, np.ndarray]:
    """((n, 2) positions, (n,) headings) of a path from `start` to exactly `goal` on the
    planner's grown grid: A* through cell centres (headings towards the next pose, the last the
    goal's), or Hybrid A* for a car of turning radius `radius_m` (arriving with the goal's
    heading). NoPath with a sentence when the goal cannot be reached."""
    grid = planner.grid
    inside = (
        grid.origin_x <= goal[0] < grid.origin_x + grid.width * grid.resolution
        and grid.origin_y <= goal[1] < grid.origin_y + grid.height * grid.resolution
    )
    where = f"({goal[0]:.2f}, {goal[1]:.2f})"
    if not inside:
        raise NoPath(
            f"the goal {where} is outside the map; goals must lie on the map", "GOAL_OUTSIDE_MAP"
        )
    goal_cell = planner._cell(goal[0], goal[1])
    if planner.blocked[goal_cell]:
        raise NoPath(
            f"the goal {where} is in or too close to an obstacle for the robot's radius; "
            "choose a goal in free space",
            "GOAL_OCCUPIED",
        )
    unreachable = (
        f"no path leads from ({start[0]:.2f}, {start[1]:.2f}) to the goal {where}: "
        "it is in a closed-off part of the map"
    )
    if kind == "hybrid_astar":
        return _hybrid(planner, start, goal, radius_m, unreachable)
    cells = astar(planner.blocked, planner._cell(start[0], start[1]), goal_cell)
    if not cells:
        raise NoPath(unreachable, "NO_VALID_PATH")
    points = np.array([planner._centre(row, col) for row, col in cells], dtype=float)
    points[-1] = goal[:2]
    return points, path_yaws(points, goal[2])


def _hybrid(planner: Any, start: Pose, goal: Pose, radius_m: float, unreachable: str) -> tuple:
    grid, blocked = planner.grid, planner.blocked
    distance = grid_distance(blocked, planner._cell(goal[0], goal[1]), grid.resolution)

    def cell(x: float, y: float) -> tuple[int, int] | None:
        col = math.floor((x - grid.origin_x) / grid.resolution)
        row = math.floor((y - grid.origin_y) / grid.resolution)
        return (row, col) if 0 <= row < grid.height and 0 <= col < grid.width else None

    def free(x: float, y: float) -> bool:
        # a robot parked against a grown obstacle may still leave the way it came
        near_start = math.hypot(x - start[0], y - start[1]) < STEP_M
        where = cell(x, y)
        return where is not None and (near_start or not blocked[where])

    def to_goal(x: float, y: float) -> float:
        where = cell(x, y)
        return math.inf if where is None else float(distance[where])

    if not math.isfinite(to_goal(start[0], start[1])) and not blocked[planner._cell(*start[:2])]:
        raise NoPath(unreachable, "NO_VALID_PATH")
    poses = hybrid_astar(start, goal, free, to_goal, grid.resolution, radius_m)
    if not poses:
        raise NoPath(
            f"no path with turns of at least {radius_m} m radius leads from "
            f"({start[0]:.2f}, {start[1]:.2f}) to the goal ({goal[0]:.2f}, {goal[1]:.2f}); "
            "a goal further from walls and doors, or the astar planner, may do",
            "NO_VALID_PATH",
        )
    # one pose per map cell of travel, as SMAC gives its path at the costmap's resolution
    every = max(1, round(grid.resolution / SAMPLE_M))
    kept = [*poses[::every][:-1], poses[-1]] if len(poses) > every else poses
    path = np.array([start, *kept], dtype=float)
    return path[:, :2].copy(), np.array([wrap(yaw) for yaw in path[:, 2]])


def path_yaws(points: np.ndarray, goal_yaw: float) -> np.ndarray:
    """Each pose's heading: towards the next pose; the last one the goal's."""
    yaws = np.full(len(points), goal_yaw)
    if len(points) > 1:
        step = np.diff(points, axis=0)
        yaws[:-1] = np.arctan2(step[:, 1], step[:, 0])
    return yaws


@dataclass
class Navigation:
    """The state of one goal while it runs."""

    uuid: bytes
    goal: Pose
    points: np.ndarray
    started_ns: int
    goal_checker: GoalChecker = field(default_factory=GoalChecker)
    progress: ProgressChecker = field(default_factory=ProgressChecker)
    pending_call: int | None = None  # the controller service call awaiting its answer
    pending_since_ns: int = 0
    missed_periods: int = 0
    service_missing_since_ns: int | None = None
    wire: Any = None  # the action it serves (navigate_to_pose or navigate_through_poses)
    via: list[tuple[float, float]] = field(default_factory=list)  # poses still to pass

    def reached(self, pose: Pose) -> bool:
        return self.goal_checker.reached(pose, self.goal)

    def distance_remaining(self, pose: Pose) -> float:
        return path_length_from(self.points, closest_index(self.points, pose[0], pose[1]))

    def eta_s(self, pose: Pose, speed_m_s: float) -> float:
        return estimated_time_s(self.distance_remaining(pose), speed_m_s)
