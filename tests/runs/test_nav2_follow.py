"""The navigation server's controller parts: Nav2's checkers, feedback values, the follower."""

from __future__ import annotations

import math

import numpy as np
import pytest

from server.runs.nav2_follow import (
    GoalChecker,
    ProgressChecker,
    PurePursuit,
    closest_index,
    estimated_time_s,
    path_length_from,
)
from server.runs.nav2_navigation import NoPath, plan_path


def test_goal_checker_is_stateful_about_xy_and_strict_about_yaw():
    checker = GoalChecker()  # Nav2's defaults: 0.25 m, 0.25 rad
    goal = (1.0, 0.0, 0.0)
    assert not checker.reached((0.70, 0.0, 0.0), goal)  # 0.30 m away
    assert not checker.reached((0.80, 0.0, 0.5), goal)  # close, facing 0.5 rad off
    assert checker.xy_reached
    # stateful: drifting out of the xy window no longer matters, only the yaw does
    assert checker.reached((0.60, 0.0, -0.2), goal)
    checker.reset()
    assert not checker.reached((0.60, 0.0, -0.2), goal)
    # yaw wraps: pi - 0.1 and -pi + 0.1 are 0.2 rad apart
    assert GoalChecker().reached((1.0, 0.0, math.pi - 0.1), (1.0, 0.0, -math.pi + 0.1))


def test_progress_checker_fails_after_ten_seconds_in_place():
    checker = ProgressChecker()
    assert checker.check(0.0, 0.0, 0.0)
    assert checker.check(0.3, 0.0, 9.9)  # within 0.5 m: no progress yet, still allowed
    assert not checker.check(0.3, 0.0, 10.1)
    assert checker.check(0.6, 0.0, 10.2)  # moved out of the circle: a new anchor
    assert checker.check(0.6, 0.0, 20.2) and not checker.check(0.6, 0.0, 20.3)


def test_feedback_distance_and_time_as_bt_navigator_computes_them():
    points = np.array([(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (2.0, 1.0)])
    assert closest_index(points, 1.1, 0.3) == 1
    assert path_length_from(points, 1) == pytest.approx(2.0)
    assert path_length_from(points, 3) == 0.0
    assert estimated_time_s(2.0, 0.25) == pytest.approx(8.0)
    assert estimated_time_s(2.0, 0.005) == 0.0  # standing still: no estimate
    assert estimated_time_s(0.05, 0.3) == 0.0  # nearly there


def drive(follower, points, goal, pose, period_s=0.05, steps=800):
    """A unicycle following the follower's commands; returns its poses."""
    checker = GoalChecker()
    x, y, yaw = pose
    trail = []
    for _ in range(steps):
        if checker.reached((x, y, yaw), goal):
            return trail, True
        v, w = follower.command((x, y, yaw), points, goal[2], checker.xy_reached, period_s)
        x += v * math.cos(yaw) * period_s
        y += v * math.sin(yaw) * period_s
        yaw += w * period_s
        trail.append((x, y, yaw, v, w))
    return trail, False


def test_follower_turns_in_place_then_tracks_an_l_shaped_path_to_the_goal_heading():
    leg_one = [(x, 0.0) for x in np.arange(0.0, 2.0, 0.05)]
    leg_two = [(2.0, y) for y in np.arange(0.0, 1.5, 0.05)]
    points = np.array(leg_one + leg_two)
    goal = (2.0, 1.5, math.pi)
    # The robot faces away from the path: it must rotate in place first.
    trail, reached = drive(PurePursuit(), points, goal, (0.0, 0.0, math.pi))
    assert reached
    assert trail[0][3] == 0.0 and trail[0][4] != 0.0
    # It cut the corner a little, no more than a lookahead's worth.
    off = [min(np.hypot(points[:, 0] - x, points[:, 1] - y)) for x, y, *_ in trail]
    assert max(off) < 0.3
    assert max(abs(v) for *_, v, _ in trail) <= 0.3 + 1e-9
    assert abs(trail[-1][3]) < 0.06  # it slowed down to arrive


class GridPlanner:
    """The planner built-in's grid, for plan_path (a 1 m x 1 m room, 10 cm cells)."""

    def __init__(self, blocked: np.ndarray) -> None:
        from types import SimpleNamespace

        self.blocked = blocked
        self.grid = SimpleNamespace(
            origin_x=0.0, origin_y=0.0, resolution=0.1, width=blocked.shape[1],
            height=blocked.shape[0],
        )  # fmt: skip

    def _cell(self, x: float, y: float) -> tuple[int, int]:
        return int(y / 0.1), int(x / 0.1)

    def _centre(self, row: int, col: int) -> tuple[float, float]:
        return (col + 0.5) * 0.1, (row + 0.5) * 0.1


def test_plans_end_at_the_goal_and_unreachable_goals_are_sentences():
    blocked = np.zeros((10, 10), dtype=bool)
    blocked[:, 5] = True
    blocked[9, 5] = False  # a gap at the top
    planner = GridPlanner(blocked)
    points, yaws = plan_path(planner, (0.15, 0.15, 0.0), (0.83, 0.21, 1.0))
    assert tuple(points[-1]) == (0.83, 0.21) and tuple(points[0]) == pytest.approx((0.15, 0.15))
    assert max(points[:, 1]) > 0.9  # through the gap
    step = points[1] - points[0]
    assert yaws[-1] == 1.0 and yaws[0] == pytest.approx(math.atan2(step[1], step[0]))
    with pytest.raises(NoPath, match=r"the goal \(0.55, 0.35\) is in or too close to an obstacle"):
        plan_path(planner, (0.15, 0.15, 0.0), (0.55, 0.35, 0.0))
    with pytest.raises(NoPath, match="is outside the map"):
        plan_path(planner, (0.15, 0.15, 0.0), (1.5, 0.5, 0.0))
    blocked[9, 5] = True
    with pytest.raises(NoPath, match=r"no path leads from \(0.15, 0.15\) to the goal"):
        plan_path(planner, (0.15, 0.15, 0.0), (0.85, 0.25, 0.0))
