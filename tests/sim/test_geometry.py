"""Point-to-segment and point-to-circle distances (server.sim.geometry)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from server.sim.geometry import (
    distance_to_nearest,
    offsets_from_segments,
    segment_arrays,
    yaw_quaternion,
)

SEGMENTS = np.array(
    [
        (0.0, 0.0, 2.0, 0.0),  # along +x
        (3.0, 1.0, 3.0, 1.0),  # zero length: a point
    ]
)


def test_offsets_point_from_the_closest_point_of_each_segment() -> None:
    offsets, distances = offsets_from_segments(np.array([1.0, 0.5]), *segment_arrays(SEGMENTS))
    np.testing.assert_allclose(offsets, [(0.0, 0.5), (-2.0, -0.5)])
    np.testing.assert_allclose(distances, [0.5, math.hypot(2.0, 0.5)])


@pytest.mark.parametrize(
    ("point", "expected_m"),
    [((-1.0, 0.0), 1.0), ((2.0, -0.25), 0.25), ((5.0, 0.0), 3.0), ((1.5, 0.0), 0.0)],
)
def test_distance_beyond_the_ends_is_to_the_endpoint(point, expected_m) -> None:
    _, distances = offsets_from_segments(np.array(point), *segment_arrays(SEGMENTS[:1]))
    assert distances[0] == pytest.approx(expected_m)


def test_distance_to_nearest_takes_segments_and_circle_surfaces() -> None:
    segments = segment_arrays(SEGMENTS)
    centres, radii = np.array([(0.0, 3.0)]), np.array([1.0])
    assert distance_to_nearest(np.array([0.0, 1.5]), segments, centres, radii) == pytest.approx(0.5)
    inside = distance_to_nearest(np.array([0.0, 2.75]), segments, centres, radii)
    assert inside == pytest.approx(-0.75)


def test_distance_to_nearest_in_an_empty_world_is_infinite() -> None:
    nothing = segment_arrays(np.zeros((0, 4)))
    assert distance_to_nearest(np.zeros(2), nothing, np.zeros((0, 2)), np.zeros(0)) == math.inf


@pytest.mark.parametrize("yaw", [0.0, 0.7, -2.5, math.pi])
def test_yaw_quaternion_is_the_unit_rotation_about_z(yaw: float) -> None:
    q = yaw_quaternion(yaw)
    assert (q.x, q.y) == (0.0, 0.0)
    assert math.hypot(*q) == pytest.approx(1.0)
    # Rotating +x by q (v' = q v q*, for a rotation about z) gives the heading vector.
    heading_x = q.w * q.w - q.z * q.z
    heading_y = 2.0 * q.w * q.z
    assert (heading_x, heading_y) == pytest.approx((math.cos(yaw), math.sin(yaw)))
