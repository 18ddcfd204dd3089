"""DepthScan: the 0.45 m slice, field of view, depth-to-range conversion, limits, seeding."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.msgs.sensor_msgs import LaserScan
from server.sim.sensors.depth_scan import DepthScan
from server.sim.state import Pose2D, RobotState
from server.sim.world import World
from tests.sim.shapes import make_context, make_world


def box(cx: float, cy: float, half: float) -> list[tuple[float, float, float, float]]:
    """The four edges of a square box centred at (cx, cy)."""
    x0, x1, y0, y1 = cx - half, cx + half, cy - half, cy + half
    return [(x0, y0, x1, y0), (x1, y0, x1, y1), (x1, y1, x0, y1), (x0, y1, x0, y0)]


def depth_ranges(
    world: World, pose: Pose2D | None = None, seed: int = 0, **options: float
) -> tuple[DepthScan, np.ndarray]:
    sensor = DepthScan(**options)
    state = RobotState(pose=pose if pose is not None else Pose2D())
    scan = sensor.sample(make_context(world, state), np.random.default_rng(seed))
    return sensor, np.asarray(scan.ranges, dtype=np.float64)


def test_a_box_lower_than_the_slice_is_invisible() -> None:
    _, ranges = depth_ranges(make_world(segments=box(1.5, 0.0, 0.25), segment_height=0.3))
    assert np.all(np.isnan(ranges))


def test_a_tall_box_is_seen() -> None:
    sensor, ranges = depth_ranges(make_world(segments=box(1.5, 0.0, 0.25), segment_height=1.0))
    centre = sensor.beam_count // 2
    assert ranges[centre] == pytest.approx(1.25, abs=0.03)
    assert np.isnan(ranges[0]) and np.isnan(ranges[-1])  # the box does not fill the view


def test_field_of_view_is_87_degrees_facing_forward() -> None:
    sensor = DepthScan()
    assert sensor.beam_angles_rad[-1] - sensor.beam_angles_rad[0] == pytest.approx(
        math.radians(87.0)
    )
    # Posts 2 m away: at 40 degrees left and right they are inside the view, at 50 outside.
    for bearing_deg, expect_seen in [(40.0, True), (-40.0, True), (50.0, False), (-50.0, False)]:
        bearing = math.radians(bearing_deg)
        post = (2.0 * math.cos(bearing), 2.0 * math.sin(bearing), 0.05)
        _, ranges = depth_ranges(make_world(circles=[post]))
        seen = ~np.isnan(ranges)
        assert seen.any() == expect_seen, bearing_deg
        if expect_seen:
            angles = sensor.beam_angles_rad[seen]
            assert np.allclose(angles, bearing, atol=math.radians(3.0))


def test_depth_is_converted_to_range_across_the_view() -> None:
    # A wall 1 m ahead: the same depth in every column, range = depth / cos(angle).
    wall = (1.0, -5.0, 1.0, 5.0)
    sensor, ranges = depth_ranges(
        make_world(segments=[wall]), depth_noise_sd_m=0.0, depth_noise_per_m2=0.0
    )
    np.testing.assert_allclose(ranges, 1.0 / np.cos(sensor.beam_angles_rad), rtol=1e-5)


@pytest.mark.parametrize("wall_x", [0.2, 3.3])
def test_out_of_range_reads_nan(wall_x: float) -> None:
    _, ranges = depth_ranges(make_world(segments=[(wall_x, -5.0, wall_x, 5.0)]))
    assert np.all(np.isnan(ranges))


def test_noise_grows_with_depth() -> None:
    def spread(wall_x: float) -> float:
        wall = (wall_x, -5.0, wall_x, 5.0)
        sensor, ranges = depth_ranges(make_world(segments=[wall]), seed=3)
        depths = ranges * np.cos(sensor.beam_angles_rad)
        assert np.count_nonzero(~np.isnan(depths)) > 100  # edge columns may be out of range
        return float(np.nanstd(depths - wall_x))

    near, far = spread(0.6), spread(2.5)
    assert far > 5.0 * near
    assert far == pytest.approx(0.001 + 0.005 * 2.5**2, rel=0.25)


def test_rotated_robot_looks_along_its_heading() -> None:
    pose = Pose2D(x=1.0, y=1.0, yaw=math.pi / 2)
    wall = (-5.0, 3.0, 5.0, 3.0)  # 2 m ahead of a robot facing +y
    sensor, ranges = depth_ranges(make_world(segments=[wall]), pose)
    assert ranges[sensor.beam_count // 2] == pytest.approx(2.0, abs=0.05)


def test_message_and_seeding() -> None:
    world = make_world(segments=[(1.5, -5.0, 1.5, 5.0)])
    sensor = DepthScan()
    scan = sensor.sample(make_context(world), np.random.default_rng(5))
    assert isinstance(scan, LaserScan)
    wire = scan.serialize()
    assert LaserScan.deserialize(wire).serialize() == wire
    assert scan.header.frame_id == "camera_depth_frame"
    assert (scan.range_min, scan.range_max) == (pytest.approx(0.3), pytest.approx(3.0))
    assert scan.scan_time == pytest.approx(1 / 15) and scan.time_increment == 0.0
    assert len(scan.ranges) == 320
    _, first = depth_ranges(world, seed=5)
    _, again = depth_ranges(world, seed=5)
    _, other = depth_ranges(world, seed=6)
    np.testing.assert_array_equal(first, np.asarray(scan.ranges, dtype=np.float64))
    np.testing.assert_array_equal(first, again)
    assert not np.array_equal(first, other)
