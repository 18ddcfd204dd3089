"""Overlays on a real viser scene: sensor nodes, the chunked trail, path, lookahead, goal."""

from __future__ import annotations

import numpy as np
import pytest

from server.viz.overlays import (
    TRAIL_CHUNK_POINTS,
    Overlays,
    lookahead_point,
    node_name,
    polyline_segments,
)
from server.viz.rays import SensorDrawing


def test_lookahead_walks_along_the_plan_from_the_nearest_point():
    plan = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)]
    assert lookahead_point(plan, 0.2, 0.3, 0.5) == pytest.approx((0.5, 0.0))
    assert lookahead_point(plan, 0.9, 0.1, 0.5) == pytest.approx((1.0, 0.5))
    assert lookahead_point(plan, 1.0, 0.9, 5.0) == pytest.approx((1.0, 1.0))  # the end
    assert lookahead_point([], 0.0, 0.0) is None


def test_names_and_polylines():
    assert node_name("ultrasonic/range_0") == "ultrasonic_range_0"
    segments = polyline_segments([(0, 0), (1, 0), (1, 1)], 0.5)
    assert segments.shape == (2, 2, 3) and (segments[:, :, 2] == 0.5).all()
    assert segments[1].tolist() == [[1, 0, 0.5], [1, 1, 0.5]]


def test_the_trail_seals_chunks_and_starts_over_when_its_start_changes(viser_server):
    overlays = Overlays(viser_server.scene, 0.1)
    trail = [(i * 0.01, 0.0) for i in range(2 * TRAIL_CHUNK_POINTS + 10)]
    overlays.draw_trail(trail[: TRAIL_CHUNK_POINTS // 2])
    assert viser_server.scene.get_handle_by_name("/trail/tail") is not None
    overlays.draw_trail(trail)
    assert len(overlays._trail_sealed) == 2
    tail = viser_server.scene.get_handle_by_name("/trail/tail")
    assert len(tail.points) == 9  # ten points after the sealed ones: nine segments
    later = trail[20:]  # the oldest points fell off: redrawn from scratch
    overlays.draw_trail(later)
    assert len(overlays._trail_sealed) == 1
    assert viser_server.scene.get_handle_by_name("/trail/1") is None
    tail = viser_server.scene.get_handle_by_name("/trail/tail")
    assert len(tail.points) == len(later) - TRAIL_CHUNK_POINTS - 1


def test_sensors_path_and_goal(viser_server):
    scene = viser_server.scene
    overlays = Overlays(scene, 0.2)
    cone = SensorDrawing("ultrasound", np.array([[0, 0, 1, 0.0]] * 3), np.zeros((0, 2)))
    scan = SensorDrawing("scan", np.zeros((0, 4)), np.array([[1.0, 2.0], [3.0, 4.0]]))
    overlays.draw_sensors(
        {"ultrasonic/range_0": cone, "scan": scan}, {"ultrasonic/range_0", "scan"}
    )
    assert scene.get_handle_by_name("/robot/readings/scan").points.shape == (2, 3)
    overlays.draw_sensors({}, {"scan"})  # nothing new; the ranger's reading is gone
    assert scene.get_handle_by_name("/robot/readings/ultrasonic_range_0").visible is False
    assert scene.get_handle_by_name("/robot/readings/scan").visible
    plan = [(0.0, 0.0), (1.0, 0.0)]
    overlays.draw_path(plan, (0.0, 0.0, 0.0), None)
    assert scene.get_handle_by_name("/route/plan").points.shape == (1, 2, 3)
    lookahead = scene.get_handle_by_name("/route/lookahead")
    assert tuple(lookahead.position[:2]) == pytest.approx((0.35, 0))
    overlays.draw_path(plan, (0.0, 0.0, 0.0), (0.7, 0.1))  # a node's own lookahead wins
    assert tuple(lookahead.position[:2]) == pytest.approx((0.7, 0.1))
    overlays.draw_goal((2.0, 3.0, 0.5))
    goal = scene.get_handle_by_name("/route/goal")
    assert tuple(goal.position) == pytest.approx((2.0, 3.0, 0.0)) and goal.visible


def test_scan_points_are_coloured_by_range_and_cones_by_reading() -> None:
    from server.viz.overlays import RANGE_STOPS, range_colours, ranger_colours

    colours = range_colours(np.array([0.0, 2.0, 100.0]))
    assert tuple(colours[0]) == RANGE_STOPS[0][1] and tuple(colours[2]) == RANGE_STOPS[-1][1]
    assert tuple(colours[1]) == RANGE_STOPS[2][1]  # half of SCAN_FAR_M
    near = ranger_colours(np.array([[0, 0, 0.1, 0]]), "ultrasound")
    far = ranger_colours(np.array([[0, 0, 3.0, 0]]), "ultrasound")
    assert near.shape == (1, 2, 3) and near[0, 0].sum() < far[0, 0].sum()  # far is paler
