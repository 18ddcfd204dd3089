"""Obstacles: the culled ray cast agrees with the dense one (its oracle) in the real worlds and in
the geometric corner cases culling could get wrong; collision queries."""

from __future__ import annotations

import math

import numpy as np
import pytest

from server.sim.obstacles import Obstacles, RayHits
from server.sim.raycast_few import cast_few
from server.sim.world import load_world
from tests.sim.shapes import make_world

SCAN = np.linspace(-math.pi, math.pi, 429, endpoint=False)  # a 360-degree LiDAR's beams


def cast_both_ways(
    obstacles: Obstacles,
    origin: tuple[float, float],
    angles: np.ndarray,
    max_range_m: float = 10.0,
    min_height_m: float = 0.0,
) -> RayHits:
    """The culled cast, after checking it (and `cast`) against the dense oracle."""
    args = (np.array(origin, dtype=float), np.asarray(angles, dtype=float), max_range_m)
    culled = obstacles._cast_culled(*args, min_height_m)
    dense = obstacles._cast_dense(*args, min_height_m)
    public = obstacles.cast(*args, min_height_m=min_height_m)
    for hits in (culled, public):
        assert hits.distance_m.shape == dense.distance_m.shape
        np.testing.assert_array_equal(np.isinf(hits.distance_m), np.isinf(dense.distance_m))
        np.testing.assert_allclose(hits.distance_m, dense.distance_m, rtol=0, atol=1e-9)
        np.testing.assert_allclose(hits.incidence_rad, dense.incidence_rad, rtol=0, atol=1e-9)
    return culled


@pytest.mark.parametrize("world_id", ["crop_rows", "office", "obstacle_maze", "wall_approach"])
def test_culled_cast_matches_dense_in_real_worlds(world_id: str) -> None:
    world = load_world(world_id)
    obstacles = Obstacles(world)
    min_x, min_y, max_x, max_y = world.bounds
    rng = np.random.default_rng(7)
    hit_count = 0
    for k in range(100):
        origin = (rng.uniform(min_x, max_x), rng.uniform(min_y, max_y))
        ray_count = int(rng.integers(1, 500))
        if k % 2:
            angles = rng.uniform(-3 * math.pi, 3 * math.pi, ray_count)  # unsorted, unwrapped
        else:
            angles = rng.uniform(-4.0, 4.0) + SCAN
        min_height_m = float(rng.choice([0.0, 0.1, 0.29, 0.45, 1.0]))
        max_range_m = float(rng.choice([0.5, 3.6, 8.0, np.inf]))
        hits = cast_both_ways(obstacles, origin, angles, max_range_m, min_height_m)
        hit_count += int(np.isfinite(hits.distance_m).sum())
    assert hit_count > 1000  # the comparison was not vacuous


@pytest.mark.parametrize("world_id", ["office", "obstacle_maze"])
def test_rays_aimed_exactly_at_segment_endpoints(world_id: str) -> None:
    world = load_world(world_id)
    obstacles = Obstacles(world)
    spawn = world.spawn()
    endpoints = world.segments.reshape(-1, 2)
    angles = np.arctan2(endpoints[:, 1] - spawn.y, endpoints[:, 0] - spawn.x)
    cast_both_ways(obstacles, (spawn.x, spawn.y), np.concatenate([angles, SCAN]), np.inf)


def test_ray_through_an_endpoint_hits_it() -> None:
    obstacles = Obstacles(make_world(segments=[(2.0, 0.0, 2.0, 1.0), (2.0, 0.0, 3.0, -1.0)]))
    hits = cast_both_ways(obstacles, (0.0, 0.0), np.concatenate([[0.0], SCAN]))
    assert hits.distance_m[0] == pytest.approx(2.0)


def test_segment_across_the_wrap_behind_the_origin() -> None:
    obstacles = Obstacles(make_world(segments=[(-2.0, -1.0, -2.0, 1.0)]))
    angles = np.array([math.pi, -math.pi, math.pi - 0.1, -math.pi + 0.1, 0.0, math.pi / 2])
    hits = cast_both_ways(obstacles, (0.0, 0.0), np.concatenate([angles, SCAN]))
    expected = [2.0, 2.0, 2.0 / math.cos(0.1), 2.0 / math.cos(0.1), np.inf, np.inf]
    np.testing.assert_allclose(hits.distance_m[:6], expected)
    assert np.isfinite(hits.distance_m[6:]).sum() == pytest.approx(
        429 * 2 * math.atan(0.5) / math.tau, abs=1
    )


def test_circle_straddling_the_wrap() -> None:
    obstacles = Obstacles(make_world(circles=[(-3.0, 0.0, 0.5)]))
    angles = np.array([math.pi, -math.pi + 0.05, math.pi - 0.05, -math.pi + 0.2])
    hits = cast_both_ways(obstacles, (0.0, 0.0), np.concatenate([angles, SCAN]))
    assert hits.distance_m[0] == pytest.approx(2.5)
    assert np.isfinite(hits.distance_m[1:3]).all()
    assert np.isinf(hits.distance_m[3])  # asin(0.5 / 3) = 0.167 rad: just past the edge


def test_ray_tangent_to_a_circle_grazes_it() -> None:
    obstacles = Obstacles(make_world(circles=[(2.0, 1.0, 1.0), (5.0, -2.0, 2.0)]))
    tangents = [0.0, -math.asin(2.0 / math.hypot(5.0, 2.0)) - math.atan2(2.0, 5.0)]
    hits = cast_both_ways(obstacles, (0.0, 0.0), np.concatenate([tangents, SCAN]))
    assert hits.distance_m[0] == 2.0  # the discriminant is exactly 0 here
    assert hits.incidence_rad[0] == pytest.approx(math.pi / 2)


def test_degenerate_segments_are_never_hit() -> None:
    obstacles = Obstacles(make_world(segments=[(1.0, 0.0, 1.0, 0.0), (0.0, 0.0, 0.0, 0.0)]))
    for origin in [(0.0, 0.0), (1.0, 0.0), (-1.0, 0.5)]:
        assert np.isinf(cast_both_ways(obstacles, origin, SCAN).distance_m).all()


@pytest.mark.parametrize("origin", [(0.0, 0.0), (1.0, 0.0), (0.3, 0.0), (2.0, 0.0)])
def test_origin_on_a_segment_or_its_line(origin: tuple[float, float]) -> None:
    obstacles = Obstacles(make_world(segments=[(-1.0, 0.0, 1.0, 0.0), (-3.0, -3.0, 3.0, -3.0)]))
    cast_both_ways(obstacles, origin, np.concatenate([[0.0, math.pi, math.pi / 2], SCAN]))


AHEAD_BEHIND_SCAN = np.concatenate([[0.0, math.pi], SCAN])  # [0], [1]: exactly along +-x


def test_surfaces_below_the_scan_plane_are_ignored() -> None:
    low_box, tall_wall = (1.0, -1.0, 1.0, 1.0), (3.0, -1.0, 3.0, 1.0)
    world = make_world(
        segments=[low_box, tall_wall], segment_height=[0.2, 2.0], circles=[(-2.0, 0.0, 0.5)]
    )
    obstacles = Obstacles(world)
    low = cast_both_ways(obstacles, (0.0, 0.0), AHEAD_BEHIND_SCAN, min_height_m=0.1)
    high = cast_both_ways(obstacles, (0.0, 0.0), AHEAD_BEHIND_SCAN, min_height_m=0.3)
    above_all = cast_both_ways(obstacles, (0.0, 0.0), AHEAD_BEHIND_SCAN, min_height_m=2.5)
    assert low.distance_m[:2] == pytest.approx([1.0, 1.5])
    assert high.distance_m[:2] == pytest.approx([3.0, 1.5])
    assert np.isinf(above_all.distance_m).all()


def test_hits_beyond_max_range_are_inf() -> None:
    obstacles = Obstacles(make_world(segments=[(5.0, -1.0, 5.0, 1.0)], circles=[(-5.0, 0.0, 1.0)]))
    short = cast_both_ways(obstacles, (0.0, 0.0), AHEAD_BEHIND_SCAN, max_range_m=3.99)
    assert np.isinf(short.distance_m).all() and np.isnan(short.incidence_rad).all()
    middle = cast_both_ways(obstacles, (0.0, 0.0), AHEAD_BEHIND_SCAN, max_range_m=4.99)
    assert middle.distance_m[0] == math.inf and middle.distance_m[1] == pytest.approx(4.0)
    exact = cast_both_ways(obstacles, (0.0, 0.0), AHEAD_BEHIND_SCAN, max_range_m=5.0)
    assert exact.distance_m[:2].tolist() == [5.0, 4.0]  # a hit at exactly max range counts


def test_empty_world_hits_nothing() -> None:
    hits = cast_both_ways(Obstacles(make_world()), (0.0, 0.0), SCAN)
    assert np.isinf(hits.distance_m).all() and np.isnan(hits.incidence_rad).all()


def test_single_ray_and_no_rays() -> None:
    obstacles = Obstacles(make_world(segments=[(2.0, -1.0, 2.0, 1.0)]))
    hits = cast_both_ways(obstacles, (0.0, 0.0), np.array([0.0]))
    assert hits.distance_m.tolist() == [2.0] and hits.incidence_rad.tolist() == [0.0]
    assert obstacles.cast(np.zeros(2), np.zeros(0), 10.0).distance_m.shape == (0,)


def test_origin_inside_a_cylinder_touches_it() -> None:
    obstacles = Obstacles(make_world(circles=[(0.0, 0.0, 0.5)], segments=[(2.0, -1.0, 2.0, 1.0)]))
    hits = cast_both_ways(obstacles, (0.1, 0.0), SCAN)
    assert (hits.distance_m == 0.0).all()


def test_one_origin_per_ray_matches_single_origin_casts() -> None:
    obstacles = Obstacles(load_world("office"))
    rng = np.random.default_rng(3)
    origins = rng.uniform([0.5, 0.5], [7.5, 5.5], size=(50, 2))
    angles = rng.uniform(-math.pi, math.pi, 50)
    together = obstacles.cast(origins, angles, 8.0, 0.29)
    for k in range(50):
        alone = obstacles.cast(origins[k], angles[k : k + 1], 8.0, 0.29)
        np.testing.assert_allclose(together.distance_m[k], alone.distance_m[0], atol=1e-9)


def test_a_lidar_scan_in_the_crop_field_takes_the_culled_path(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    world = load_world("crop_rows")
    obstacles = Obstacles(world)

    def no_dense(*_: object) -> RayHits:
        raise AssertionError("a 429-beam scan in crop_rows fell back to the dense cast")

    monkeypatch.setattr(obstacles, "_cast_dense", no_dense)
    spawn = world.spawn()
    hits = obstacles.cast(np.array([spawn.x, spawn.y]), SCAN, 8.0, min_height_m=0.29)
    assert np.isfinite(hits.distance_m).any()


def test_disc_is_pushed_out_of_a_wall_corner() -> None:
    obstacles = Obstacles(make_world(segments=[(0.0, 0.0, 2.0, 0.0), (0.0, 0.0, 0.0, 2.0)]))
    push, angle = obstacles.penetrations(0.1, 0.2, 0.3)
    order = np.argsort(push[:, 0])  # the y = 0 wall first, then the x = 0 wall
    np.testing.assert_allclose(push[order], [[0.0, 0.1], [0.2, 0.0]], atol=1e-12)
    towards_wall = np.stack([np.cos(angle[order]), np.sin(angle[order])], axis=1)
    np.testing.assert_allclose(towards_wall, [[0.0, -1.0], [-1.0, 0.0]], atol=1e-12)
    x, y = np.array([0.1, 0.2]) + push.sum(axis=0)
    assert obstacles.penetrations(x, y, 0.3 - 1e-9)[0].shape == (0, 2)


def test_disc_overlapping_a_cylinder_and_nothing_touching() -> None:
    obstacles = Obstacles(make_world(circles=[(1.0, 0.0, 0.5)]))
    push, angle = obstacles.penetrations(0.4, 0.0, 0.2)
    np.testing.assert_allclose(push, [[-0.1, 0.0]], atol=1e-12)
    assert angle == pytest.approx([0.0])
    push, angle = obstacles.penetrations(-1.0, 0.0, 0.2)
    assert push.shape == (0, 2) and angle.shape == (0,)


def test_clearance_to_cylinders_and_walls() -> None:
    obstacles = Obstacles(make_world(circles=[(3.0, 4.0, 1.0)], segments=[(-2.0, -9.0, -2.0, 9.0)]))
    assert obstacles.clearance(0.0, 0.0) == pytest.approx(2.0)
    assert obstacles.clearance(3.0, 2.0) == pytest.approx(1.0)
    assert obstacles.clearance(3.0, 4.5) < 0.0  # inside the cylinder
    assert Obstacles(make_world()).clearance(0.0, 0.0) == math.inf


@pytest.mark.parametrize("world_id", ["wall_approach", "light_arena", "obstacle_maze"])
def test_few_ray_python_cast_matches_dense(world_id: str) -> None:
    obstacles = Obstacles(load_world(world_id))
    rng = np.random.default_rng(11)
    surfaces = obstacles.segment_height.size + obstacles.circle_height.size
    rays = max(1, min(7, 160 // surfaces))  # small enough for the plain-Python path
    for _ in range(300):
        origin = rng.uniform([0.0, 0.0], [3.0, 2.5])
        angles = rng.uniform(-math.pi, math.pi) + np.linspace(-0.13, 0.13, rays)
        min_height = float(rng.choice([0.0, 0.2]))
        few = obstacles.cast(origin, angles, 2.0, min_height)
        dense = obstacles._cast_dense(origin, angles, 2.0, min_height)
        np.testing.assert_array_equal(np.isinf(few.distance_m), np.isinf(dense.distance_m))
        finite = np.isfinite(dense.distance_m)
        np.testing.assert_allclose(few.distance_m[finite], dense.distance_m[finite], atol=1e-9)
        np.testing.assert_allclose(
            few.incidence_rad[finite], dense.incidence_rad[finite], atol=1e-7
        )


def test_the_small_cast_leaves_out_only_surfaces_out_of_reach() -> None:
    """cast_small culls surfaces beyond the range before its loop; every reading equals the
    loop over every surface, exactly, including hits just inside the range and rays that start
    inside a cylinder."""
    world = make_world(
        segments=[(1.0, -1.0, 1.0, 1.0), (2.0, -0.5, 2.0, 0.5), (-3.0, -3.0, 3.0, -3.0)],
        circles=[(0.0, 1.5, 0.3), (0.0, 0.0, 0.2), (4.0, 4.0, 0.5)],
    )
    obstacles = Obstacles(world)
    rng = np.random.default_rng(5)
    culled_any = False
    for _ in range(2000):
        origin = rng.uniform(-3.0, 3.0, 2)
        angles = (rng.uniform(-math.pi, math.pi) + np.linspace(-0.13, 0.13, 7)).tolist()
        max_range = float(rng.choice([0.5, 1.0, 2.0]))
        small = obstacles.cast_small(float(origin[0]), float(origin[1]), angles, max_range)
        whole = cast_few(
            obstacles._few_segments, obstacles._few_circles, *origin.tolist(), angles,
            max_range, 0.0,
        )  # fmt: skip
        assert small is not None
        np.testing.assert_array_equal(small[0], whole[0])  # distances, bit for bit
        np.testing.assert_array_equal(small[1], whole[1])  # cosines (nan where nothing)
        culled_any |= any(
            math.hypot(x - origin[0], y - origin[1]) - half > max_range
            for x, y, half in obstacles._few_segment_bounds
        )
    assert culled_any  # the case the culling is for did occur


def test_a_large_world_is_not_cast_small() -> None:
    obstacles = Obstacles(load_world("obstacle_maze"))
    surfaces = obstacles.segment_height.size + obstacles.circle_height.size
    assert surfaces * 7 > 160
    assert obstacles.cast_small(1.0, 1.0, [0.0] * 7, 2.0) is None


def test_few_ray_cast_with_circles_and_heights() -> None:
    world = make_world(
        segments=[(1.0, -1.0, 1.0, 1.0), (0.5, 0.3, 0.8, 0.3)],
        segment_height=[0.3, 0.1],
        circles=[(0.6, 0.0, 0.05), (0.0, 0.0, 0.2)],
    )
    obstacles = Obstacles(world)
    angles = np.linspace(-0.5, 0.5, 9)
    for origin, min_height in (((0.0, 0.5), 0.0), ((0.0, 0.5), 0.2), ((0.0, 0.0), 0.0)):
        few = obstacles.cast(np.array(origin), angles, 3.0, min_height)
        dense = obstacles._cast_dense(np.array(origin), angles, 3.0, min_height)
        np.testing.assert_allclose(few.distance_m, dense.distance_m, atol=1e-12)


@pytest.mark.parametrize("world_id", ["wall_approach", "obstacle_maze", "office", "crop_rows"])
def test_contact_queries_agree_between_python_and_numpy(world_id: str) -> None:
    fast = Obstacles(load_world(world_id))
    batched = Obstacles(load_world(world_id))
    batched._few_surfaces = False  # force the numpy path
    rng = np.random.default_rng(5)
    for _ in range(400):
        x, y = rng.uniform([-0.2, -0.2], [8.0, 6.0])
        radius = float(rng.uniform(0.05, 0.3))
        assert fast.clearance(x, y) == pytest.approx(batched.clearance(x, y), abs=1e-12)
        push_fast, angle_fast = fast.penetrations(x, y, radius)
        push_numpy, angle_numpy = batched.penetrations(x, y, radius)
        np.testing.assert_allclose(push_fast, push_numpy, atol=1e-12)
        # Compare directions, not numbers: -pi and pi are the same way (a signed zero apart).
        np.testing.assert_allclose(np.angle(np.exp(1j * (angle_fast - angle_numpy))), 0, atol=1e-9)
        # One pass gives both answers, each path the same as its own two queries.
        for obstacles, push, angle in (
            (fast, push_fast, angle_fast),
            (batched, push_numpy, angle_numpy),
        ):
            both_push, both_angle, nearest = obstacles.contacts(x, y, radius)
            np.testing.assert_array_equal(both_push, push)
            np.testing.assert_array_equal(both_angle, angle)
            assert nearest == obstacles.clearance(x, y)
