"""The sim-vs-real comparison's pure parts: the time base, the zero-order hold and the sentences
that state the gap (server/service/comparison.py)."""

from __future__ import annotations

import math

import pytest

from server.service.comparison import check_sentence, compare_checks, resample, time_base


def test_the_time_base_is_10_hz_and_coarser_for_long_runs():
    grid = time_base(2.0)
    assert grid[0] == 0.0 and grid[-1] == pytest.approx(2.0) and len(grid) == 21
    assert len(time_base(3600.0)) <= 3001  # an hour is not 36,000 points per series


def test_samples_are_held_and_end_with_the_series():
    grid = time_base(3.0)
    held = resample([0.25, 1.0], [5.0, 7.0], grid)
    assert held[:3] == [None, None, None]  # before the first message: nothing measured
    assert held[3] == 5.0 and held[9] == 5.0 and held[10] == 7.0  # held until the next one
    assert held[15] == 7.0 and held[16] is None  # 0.5 s past the last message, it ends
    assert resample([0.0], [math.nan], grid)[0] is None  # no NaN in JSON


def test_the_gap_is_said_in_a_sentence():
    assert check_sentence("settling_time", "s", "<=", 14.5, 17.2) == (
        "settling time: 14.5 s in simulation, 17.2 s on the robot: 2.7 s slower"
    )
    assert check_sentence("settling_time", "s", "<=", 9.0, 8.5).endswith("0.5 s faster")
    assert check_sentence("overshoot", "m", "<=", 0.02, 0.05) == (
        "overshoot: 0.02 m in simulation, 0.05 m on the robot: 0.03 m more (worse)"
    )
    assert check_sentence("tracked", "", ">=", 3, 2).endswith("1 less (worse)")
    assert check_sentence("collisions", "", "<=", 0, 0).endswith("the same")
    never = check_sentence("settling_time", "s", "<=", 14.5, None)
    assert "nothing to judge on the robot" in never and "ended before" in never
    assert "in either run" in check_sentence("settling_time", "s", "<=", None, None)


def test_checks_are_matched_by_name():
    a = {"name": "a", "unit": "s", "comparison": "<=", "threshold": 2.0}
    sim = [{**a, "value": 1.0, "passed": True}]
    real = [{**a, "value": 3.0, "passed": False}, {"name": "b", "value": None, "passed": False}]
    rows = compare_checks(sim, real)
    assert [r["name"] for r in rows] == ["a", "b"]
    assert rows[0]["difference"] == 2.0 and rows[0]["hardware"]["passed"] is False
    assert rows[1]["simulation"]["value"] is None and rows[1]["difference"] is None
