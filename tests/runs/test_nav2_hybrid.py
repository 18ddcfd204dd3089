"""Hybrid A* of the nav2 built-in: Dubins words that end where they should, and searches that
go around walls with no turn tighter than the minimum radius, arriving with the goal's heading."""

from __future__ import annotations

import itertools
import math
import random

import numpy as np
import pytest

from server.runs.nav2_hybrid import drive, dubins_words, grid_distance, hybrid_astar
from server.runs.nav2_navigation import NoPath, plan_path


def test_every_dubins_word_ends_at_the_goal_pose():
    rng = random.Random(7)
    checked = 0
    for _ in range(200):
        q0 = (rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-4, 4))
        q1 = (rng.uniform(-3, 3), rng.uniform(-3, 3), rng.uniform(-4, 4))
        radius = rng.uniform(0.2, 1.0)
        words = dubins_words(q0, q1, radius)
        assert words, (q0, q1)  # LSL/RSR-type words always exist for a forward car
        lengths = [sum(w[1]) for w in words]
        assert lengths == sorted(lengths)
        for word, parts in words:
            moves = [
                (k, p * (radius if k == "S" else 1.0)) for k, p in zip(word, parts, strict=True)
            ]
            x, y, yaw = drive(q0, moves, radius, 0.01)[-1]
            assert math.hypot(x - q1[0], y - q1[1]) < 1e-6
            assert abs(math.remainder(yaw - q1[2], 2 * math.pi)) < 1e-6
            checked += 1
    assert checked > 400


def room_with_a_wall():
    """4 m x 3 m at 5 cm cells; a wall across x = 2 m with a gap at the top."""
    blocked = np.zeros((60, 80), dtype=bool)
    blocked[:, :2] = blocked[:, -2:] = blocked[:2, :] = blocked[-2:, :] = True
    blocked[:44, 38:42] = True
    return blocked


def test_hybrid_astar_goes_round_the_wall_turning_no_tighter_than_its_radius():
    blocked = room_with_a_wall()

    def cell(x, y):
        return int(y / 0.05), int(x / 0.05)

    def free(x, y):
        row, col = cell(x, y)
        return 0 <= row < 60 and 0 <= col < 80 and not blocked[row, col]

    distance = grid_distance(blocked, cell(3.0, 0.5), 0.05)

    def to_goal(x, y):
        return float(distance[cell(x, y)])

    poses = hybrid_astar((1.0, 0.5, 0.0), (3.0, 0.5, -math.pi / 2), free, to_goal, 0.05, 0.4)
    assert poses and all(free(x, y) for x, y, _ in poses)
    assert max(y for _, y, _ in poses) > 2.2  # through the gap
    x, y, yaw = poses[-1]
    assert (x, y) == pytest.approx((3.0, 0.5)) and math.sin(yaw) == pytest.approx(-1.0)
    for (x0, y0, a0), (x1, y1, a1) in itertools.pairwise(poses):
        step = math.hypot(x1 - x0, y1 - y0)
        turn = abs(math.remainder(a1 - a0, 2 * math.pi))
        # curvature at most 1 / radius: the chord of an arc of radius 0.4 m turning by `turn`
        assert turn <= 2 * math.asin(min(1.0, step / 0.8)) + 1e-9


class Grid:
    def __init__(self, blocked):
        from types import SimpleNamespace

        self.blocked = blocked
        self.grid = SimpleNamespace(
            origin_x=0.0, origin_y=0.0, resolution=0.05, width=80, height=60
        )

    def _cell(self, x, y):
        return int(y / 0.05), int(x / 0.05)

    def _centre(self, row, col):
        return (col + 0.5) * 0.05, (row + 0.5) * 0.05


def test_plan_path_with_hybrid_astar_gives_headings_and_sentences():
    planner = Grid(room_with_a_wall())
    points, yaws = plan_path(planner, (1.0, 0.5, 0.0), (3.0, 0.5, math.pi), "hybrid_astar")
    assert tuple(points[-1]) == pytest.approx((3.0, 0.5))
    assert math.cos(yaws[-1]) == pytest.approx(-1.0)
    assert np.hypot(*np.diff(points, axis=0).T).max() < 0.06  # one pose per cell of travel
    closed = room_with_a_wall()
    closed[40:, 38:42] = True  # the gap walled up
    with pytest.raises(NoPath, match=r"no path leads from \(1.00, 0.50\) to the goal"):
        plan_path(Grid(closed), (1.0, 0.5, 0.0), (3.0, 0.5, 0.0), "hybrid_astar")
