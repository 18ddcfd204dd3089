"""turtlebot_stanley: the reference's geometry (eq. 5.1-5.6, 2.16) on hand-made cases, the
checks on hand-made paths, and the pure pursuit tracker it is compared with also reaching every
waypoint."""

from __future__ import annotations

import dataclasses
import importlib.util
import math

import numpy as np
import pytest

from server.exercises import turtlebot
from server.exercises.grading import grade
from server.exercises.model import EXERCISE_DIR
from server.runs.spec import NodeSpec


def _load(relative: str):
    spec = importlib.util.spec_from_file_location(
        relative.replace("/", "_"), EXERCISE_DIR / relative
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


stanley = _load("reference/turtlebot_stanley.py")
pursuit = _load("reference/turtlebot_pure_pursuit.py")


def test_wrap_angle_lands_in_minus_pi_to_pi():
    assert stanley.wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    assert stanley.wrap_angle(-math.pi) == pytest.approx(math.pi)
    assert stanley.wrap_angle(0.3) == pytest.approx(0.3)


def test_smoothing_keeps_the_ends_and_flattens_a_staircase():
    stairs = np.array([(i * 0.05, (i // 2) * 0.05) for i in range(20)])
    smooth = stanley.smooth_path(stairs)
    assert np.allclose(smooth[0], stairs[0]) and np.allclose(smooth[-1], stairs[-1])
    headings = np.arctan2(*np.diff(smooth, axis=0).T[::-1])
    assert np.ptp(headings[4:-4]) < np.ptp(np.arctan2(*np.diff(stairs, axis=0).T[::-1]))


def test_closest_point_projects_onto_a_segment():
    path = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)])
    index, point = stanley.closest_point(path, 0.4, -0.3)
    assert index == 0 and np.allclose(point, (0.4, 0.0))
    index, point = stanley.closest_point(path, 1.2, 0.7)
    assert index == 1 and np.allclose(point, (1.0, 0.7))


def test_point_at_arc_walks_along_and_clamps():
    path = np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)])
    arc = stanley.arc_lengths(path)
    assert np.allclose(arc, (0.0, 1.0, 2.0))
    assert np.allclose(stanley.point_at_arc(path, arc, 1.5), (1.0, 0.5))
    assert np.allclose(stanley.point_at_arc(path, arc, 9.0), (1.0, 1.0))


def test_lateral_error_is_positive_to_the_right_of_the_path():
    """Path along +x; eq. 5.6 makes e_y > 0 when the robot is right of it (y < 0), so that
    arctan(k e_y / v) in eq. 2.16 turns the robot left, back to the path."""
    t1, t2 = (0.0, 0.0), (1.0, 0.0)
    e_y, e_gamma = stanley.stanley_errors(t1, t2, 0.0, -0.2, 0.0)
    assert e_y == pytest.approx(0.2) and e_gamma == pytest.approx(0.0)
    e_y, e_gamma = stanley.stanley_errors(t1, t2, 0.0, 0.2, 0.5)
    assert e_y == pytest.approx(-0.2) and e_gamma == pytest.approx(-0.5)


def test_heading_command_is_clipped_to_gamma_max():
    assert stanley.stanley_heading(0.0, 0.3, 0.3) == pytest.approx(0.3)
    assert stanley.stanley_heading(0.1, 0.0, 0.3, k=1.5) == pytest.approx(math.atan(0.5))
    assert stanley.stanley_heading(5.0, 1.0, 0.3) == stanley.GAMMA_F_MAX_RAD
    assert stanley.stanley_heading(-5.0, -1.0, 0.3) == -stanley.GAMMA_F_MAX_RAD


def test_speed_slows_near_the_end_and_when_facing_away():
    assert stanley.forward_speed(5.0, 0.0) == pytest.approx(stanley.CRUISE_M_S)
    assert stanley.forward_speed(0.3, 0.0) < stanley.CRUISE_M_S
    assert stanley.forward_speed(5.0, 2.0) == 0.0
    assert stanley.forward_speed(0.01, 0.0) == 0.0


def test_pursuit_curvature_is_that_of_the_arc_through_the_goal():
    # A goal 1 m to the left: the circle through it tangent to the heading has radius 0.5 m.
    assert pursuit.pursuit_curvature(0.0, 0.0, 0.0, 0.0, 1.0, 1.0) == pytest.approx(2.0)
    assert pursuit.pursuit_curvature(0.0, 0.0, 0.0, 1.0, 0.0, 1.0) == pytest.approx(0.0)


def test_distance_to_polyline():
    path = np.array([(0.0, 0.0), (1.0, 0.0)])
    distances = turtlebot._distance_to_polyline(path, np.array([0.5, 2.0]), np.array([0.1, 0.0]))
    assert np.allclose(distances, (0.1, 1.0))


@pytest.mark.slow
def test_pure_pursuit_also_reaches_every_waypoint(launcher, tmp_path):
    exercise = dataclasses.replace(turtlebot.TURTLEBOT_STANLEY, seeds=(1,))
    node = NodeSpec.from_file(EXERCISE_DIR / "reference/turtlebot_pure_pursuit.py", "pursuit")
    result = grade(exercise, (node,), launcher, tmp_path)
    checks = {check.name: check for check in result.checks}
    assert checks["waypoints_reached"].passed, checks["waypoints_reached"]
    assert checks["collisions"].passed, checks["collisions"]
