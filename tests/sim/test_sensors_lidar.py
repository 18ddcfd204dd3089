"""Lidar2D: the paper's mount convention, gaps between plants, range limits, seeding."""

from __future__ import annotations

import math

import numpy as np
import pytest

from sandbox.msgs.sensor_msgs import LaserScan
from server.sim.sensors.lidar import Lidar2D
from server.sim.state import Pose2D, RobotState
from server.sim.world import World
from tests.sim.shapes import make_context, make_world


def scan_ranges(
    world: World, pose: Pose2D | None = None, seed: int = 0, **options: float
) -> tuple[Lidar2D, np.ndarray]:
    lidar = Lidar2D(**options)
    state = RobotState(pose=pose if pose is not None else Pose2D())
    scan = lidar.sample(make_context(world, state), np.random.default_rng(seed))
    return lidar, np.asarray(scan.ranges, dtype=np.float64)


def beam_nearest(lidar: Lidar2D, angle_rad: float) -> int:
    """Index of the beam whose (wrapped) lidar angle is closest to `angle_rad`."""
    difference = np.angle(np.exp(1j * (lidar.beam_angles_rad - angle_rad)))
    return int(np.argmin(np.abs(difference)))


def rotated(points: list[tuple[float, float]], pose: Pose2D) -> tuple[float, ...]:
    """Robot-frame points moved to the world frame of `pose`, flattened."""
    c, s = math.cos(pose.yaw), math.sin(pose.yaw)
    out: list[float] = []
    for x, y in points:
        out += [pose.x + c * x - s * y, pose.y + s * x + c * y]
    return tuple(out)


@pytest.mark.parametrize("pose", [Pose2D(), Pose2D(x=1.5, y=-2.0, yaw=2.3)])
def test_wall_on_the_left_appears_between_zero_and_pi(pose: Pose2D) -> None:
    wall = rotated([(-3.0, 1.0), (3.0, 1.0)], pose)  # 1 m to the robot's left
    lidar, ranges = scan_ranges(make_world(segments=[wall]), pose)
    seen = ranges > 0.0
    assert seen.sum() > 100
    angles = lidar.beam_angles_rad[seen]
    assert np.all((angles > 0.0) & (angles < math.pi))
    assert ranges[beam_nearest(lidar, math.pi / 2)] == pytest.approx(1.0, abs=0.03)


def test_wall_on_the_right_appears_between_minus_pi_and_zero() -> None:
    lidar, ranges = scan_ranges(make_world(segments=[(-3.0, -0.8, 3.0, -0.8)]))
    angles = lidar.beam_angles_rad[ranges > 0.0]
    assert angles.size > 100 and np.all(angles < 0.0)
    assert ranges[beam_nearest(lidar, -math.pi / 2)] == pytest.approx(0.8, abs=0.03)


def test_wall_behind_is_at_angle_zero_and_front_at_pi() -> None:
    behind = (-1.0, -5.0, -1.0, 5.0)
    lidar, ranges = scan_ranges(make_world(segments=[behind]))
    assert ranges[beam_nearest(lidar, 0.0)] == pytest.approx(1.0, abs=0.03)
    assert ranges[beam_nearest(lidar, math.pi)] == 0.0  # nothing in front

    front = (2.0, -5.0, 2.0, 5.0)
    lidar, ranges = scan_ranges(make_world(segments=[front]))
    assert ranges[0] == pytest.approx(2.0, abs=0.03)  # angle_min = -pi: straight ahead
    assert ranges[beam_nearest(lidar, 0.0)] == 0.0


def test_angles_sweep_clockwise() -> None:
    # A post ahead and to the right: robot-frame bearing -30 deg -> lidar angle pi + 30 deg,
    # which wraps to -150 deg.
    bearing = math.radians(-30.0)
    post = (2.0 * math.cos(bearing), 2.0 * math.sin(bearing), 0.05)
    lidar, ranges = scan_ranges(make_world(circles=[post]))
    hit_angles = lidar.beam_angles_rad[ranges > 0.0]
    assert hit_angles.size > 0
    assert np.allclose(hit_angles, math.radians(-150.0), atol=math.radians(3.0))


def test_beams_pass_through_a_gap_between_plants() -> None:
    plants = [(1.0, 0.15, 0.1), (1.0, -0.15, 0.1)]  # a 0.1 m gap straight ahead
    wall = (3.0, -5.0, 3.0, 5.0)
    lidar, ranges = scan_ranges(make_world(segments=[wall], circles=plants))
    assert ranges[0] == pytest.approx(3.0, abs=0.05)  # straight ahead, through the gap
    at_plant = beam_nearest(lidar, math.pi - math.atan2(0.15, 1.0))
    assert ranges[at_plant] == pytest.approx(math.hypot(1.0, 0.15) - 0.1, abs=0.03)


def test_geometry_under_the_scan_plane_is_not_seen() -> None:
    low_plant = [(1.0, 0.0, 0.1)]
    _, ranges = scan_ranges(make_world(circles=low_plant, circle_height=0.2))
    assert np.all(ranges == 0.0)
    _, ranges = scan_ranges(make_world(circles=low_plant, circle_height=0.5))
    assert ranges[0] == pytest.approx(0.9, abs=0.03)


def test_range_limits_report_zero() -> None:
    too_close = (0.1, 0.0, 0.03)  # surface 7 cm ahead, under range_min
    far_wall = (9.0, -20.0, 9.0, 20.0)  # beyond range_max everywhere ahead
    near_wall = (-1.0, -20.0, -1.0, 20.0)  # behind: some beams in range
    lidar, ranges = scan_ranges(make_world(segments=[far_wall, near_wall], circles=[too_close]))
    assert ranges[0] == 0.0
    assert ranges[beam_nearest(lidar, math.pi / 2)] == 0.0  # sideways: no return at all
    valid = ranges[ranges > 0.0]
    assert valid.size > 100
    assert np.all((valid >= lidar.range_min_m) & (valid <= lidar.range_max_m))

    lidar, ranges = scan_ranges(make_world(segments=[(7.5, -20.0, 7.5, 20.0)]))
    assert ranges[0] == pytest.approx(7.5, abs=0.1)


def test_message_layout_follows_the_datasheet() -> None:
    world = make_world(segments=[(2.0, -5.0, 2.0, 5.0)])
    lidar = Lidar2D()
    scan = lidar.sample(make_context(world), np.random.default_rng(0))
    wire = scan.serialize()
    assert LaserScan.deserialize(wire).serialize() == wire
    assert len(scan.ranges) == lidar.beam_count == round(3000 / 7)
    assert scan.angle_min == pytest.approx(-math.pi)
    assert scan.angle_max == pytest.approx(math.pi - scan.angle_increment)
    assert scan.angle_increment == pytest.approx(2 * math.pi / lidar.beam_count)
    assert scan.time_increment == pytest.approx(1 / 3000)
    assert scan.scan_time == pytest.approx(1 / 7)
    assert (scan.range_min, scan.range_max) == (pytest.approx(0.12), pytest.approx(8.0))
    assert scan.header.frame_id == "laser"
    assert lidar.rate_hz == pytest.approx(7.0) and lidar.phase_s == 0.0


def test_mount_offset_moves_the_origin_forward() -> None:
    world = make_world(segments=[(2.0, -5.0, 2.0, 5.0)])
    _, ranges = scan_ranges(world, mount_forward_m=0.1, noise_sd_m=0.0, noise_sd_per_m=0.0)
    assert ranges[0] == pytest.approx(1.9, abs=1e-5)


def test_noise_is_seeded() -> None:
    world = make_world(segments=[(2.0, -5.0, 2.0, 5.0), (-2.0, -5.0, -2.0, 5.0)])
    _, first = scan_ranges(world, seed=1)
    _, again = scan_ranges(world, seed=1)
    _, other = scan_ranges(world, seed=2)
    np.testing.assert_array_equal(first, again)
    assert not np.array_equal(first, other)
    exact = np.abs(first[0] - 2.0)
    assert 0.0 < exact < 0.06  # noisy, about 1 cm


@pytest.mark.parametrize(
    "options",
    [{"range_min_m": 0.0}, {"range_min_m": 9.0}, {"rate_hz": 0.0}, {"sample_rate_hz": 10.0}],
)
def test_bad_configuration_is_refused(options: dict[str, float]) -> None:
    with pytest.raises(ValueError, match="Lidar2D needs"):
        Lidar2D(**options)
