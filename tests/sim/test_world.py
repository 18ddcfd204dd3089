"""The registered worlds: each loads, passes the validator and is the lab setup it claims to be."""

from __future__ import annotations

import itertools
import math
import tomllib
from collections import deque
from importlib import resources

import numpy as np
import pytest

from server.sim.checks import check_world
from server.sim.world import (
    KNOWN_ROBOT_IDS,
    GridMap,
    World,
    WorldError,
    load_world,
    parse_world,
    rasterize,
    world_ids,
)

WORLD_IDS = ("crop_rows", "light_arena", "line_track", "obstacle_maze", "office", "wall_approach")


def _file_data(world_id: str) -> dict:
    text = resources.files("server.sim.worlds").joinpath(f"{world_id}.toml").read_text()
    return tomllib.loads(text)


def test_registry_lists_the_packaged_worlds() -> None:
    assert world_ids() == WORLD_IDS


@pytest.mark.parametrize("world_id", WORLD_IDS)
def test_world_loads_and_holds_its_invariants(world_id: str) -> None:
    world = load_world(world_id)
    assert world.id == world_id == _file_data(world_id)["id"]
    assert load_world(world_id) is world  # cached
    check_world(world)
    assert world.segments.ndim == 2 and world.segments.shape[1] == 4
    assert np.isfinite(world.segments).all() and np.isfinite(world.circles).all()
    assert set(world.robots) <= set(KNOWN_ROBOT_IDS) and world.robots
    for spawn in world.spawns:
        assert world.in_bounds(spawn.x, spawn.y)
        assert world.clearance(spawn.x, spawn.y) >= 0.1, spawn.name
    tape_points = world.tape_segments.reshape(-1, 2)
    assert all(world.in_bounds(x, y) for x, y in tape_points)
    assert 0.0 <= world.ambient_light <= 1.0 and 0.0 <= world.floor_reflectance <= 1.0
    arrays = (world.segments, world.segment_height, world.circles, world.tape_segments)
    assert not any(array.flags.writeable for array in arrays)  # shared between runs: read-only


def test_unknown_world_id_lists_the_valid_ids() -> None:
    with pytest.raises(WorldError) as caught:
        load_world("ofice")
    assert "unknown world 'ofice'" in str(caught.value)
    assert "valid ids: " + ", ".join(WORLD_IDS) in str(caught.value)


def test_unknown_spawn_name_lists_the_spawns() -> None:
    world = load_world("office")
    assert world.spawn() is world.spawns[0] and world.spawn("corridor").name == "corridor"
    with pytest.raises(WorldError, match=r"has no spawn 'kitchen'; choose one of: start, corridor"):
        world.spawn("kitchen")


def test_validator_refuses_a_spawn_inside_a_box() -> None:
    data = _file_data("obstacle_maze")
    box = data["boxes"][0]
    data["spawns"][0].update(x=box["x"], y=box["y"])
    world = parse_world(data, "obstacle_maze.toml")
    assert world.clearance(box["x"], box["y"]) < 0
    with pytest.raises(WorldError, match=r"spawn 'start' leaves -0\.1"):
        check_world(world)


def _ray_distance(world: World, x: float, y: float, yaw: float) -> float:
    """Distance [m] from (x, y) along `yaw` to the first segment."""
    direction = np.array([math.cos(yaw), math.sin(yaw)])
    best = math.inf
    for x1, y1, x2, y2 in world.segments:
        edge = np.array([x2 - x1, y2 - y1])
        denom = direction[0] * -edge[1] + direction[1] * edge[0]
        if abs(denom) < 1e-12:
            continue
        rel = np.array([x1 - x, y1 - y])
        t = (rel[0] * -edge[1] + rel[1] * edge[0]) / denom
        s = (direction[0] * rel[1] - direction[1] * rel[0]) / denom
        if t > 0 and 0 <= s <= 1:
            best = min(best, t)
    return best


def test_wall_approach_starts_0_6_m_from_the_wall_ahead() -> None:
    world = load_world("wall_approach")
    start = world.spawn("start")
    sensor_offset = 0.05  # [m] robot centre behind its ultrasonic sensor
    ahead = _ray_distance(world, start.x, start.y, start.yaw)
    assert ahead - sensor_offset == pytest.approx(0.6, abs=0.01)
    width, depth = world.bounds[2] - world.bounds[0], world.bounds[3] - world.bounds[1]
    assert (width, depth) == (1.5, 1.0)


def test_light_arena_lamp_is_movable_and_0_6_m_from_the_centre() -> None:
    world = load_world("light_arena")
    (lamp,) = world.lights
    centre = world.spawn()
    assert lamp.name == "lamp" and lamp.movable and lamp.intensity == 3.0  # a desk lamp
    assert math.hypot(lamp.x - centre.x, lamp.y - centre.y) == pytest.approx(0.6)
    assert (centre.x, centre.y) == (1.0, 1.0)


def test_line_track_is_a_smooth_closed_loop_under_the_start() -> None:
    world = load_world("line_track")
    tape = world.tape_segments
    lengths = np.hypot(*(tape[:, 2:] - tape[:, :2]).T)
    assert lengths.max() <= 0.05 + 1e-9
    np.testing.assert_allclose(tape[1:, :2], tape[:-1, 2:])  # each piece starts where one ended
    np.testing.assert_allclose(tape[-1, 2:], tape[0, :2])  # and the loop closes
    # A 1.6 m x 1.0 m rectangle with 0.3 m corner arcs: 2 * (1.6 + 1.0) - (8 - 2 pi) * 0.3.
    assert lengths.sum() == pytest.approx(5.2 - (8 - 2 * math.pi) * 0.3, abs=0.01)
    xs, ys = tape[:, [0, 2]], tape[:, [1, 3]]
    assert xs.max() - xs.min() == pytest.approx(1.6) and ys.max() - ys.min() == pytest.approx(1.0)
    # Turning never more than ~15 deg from one 5 cm piece to the next: smooth for line sensors.
    headings = np.unwrap(np.arctan2(tape[:, 3] - tape[:, 1], tape[:, 2] - tape[:, 0]))
    assert np.abs(np.diff(headings)).max() < math.radians(15)
    assert headings[-1] - headings[0] == pytest.approx(2 * math.pi, abs=0.3)  # anticlockwise
    start = world.spawn("start")
    nearest = np.argmin([_point_to_segment(start.x, start.y, *seg) for seg in tape])
    assert _point_to_segment(start.x, start.y, *tape[nearest]) < world.tape_width[nearest] / 2
    assert math.cos(start.yaw - headings[nearest]) > math.cos(math.radians(10))
    assert world.tape_width.tolist() == [0.025] * len(tape)
    assert world.floor_reflectance > 0.7 and world.tape_darkness.min() > 0.9


def _point_to_segment(x: float, y: float, x1: float, y1: float, x2: float, y2: float) -> float:
    dx, dy = x2 - x1, y2 - y1
    t = min(1.0, max(0.0, ((x - x1) * dx + (y - y1) * dy) / (dx * dx + dy * dy)))
    return math.hypot(x - x1 - t * dx, y - y1 - t * dy)


def _segment_gap(a: np.ndarray, b: np.ndarray) -> float:
    """Shortest distance between two segments (0 if they cross)."""
    (ax1, ay1, ax2, ay2), (bx1, by1, bx2, by2) = a, b

    def side(px, py, qx, qy, rx, ry):
        return (qx - px) * (ry - py) - (qy - py) * (rx - px)

    d1, d2 = side(ax1, ay1, ax2, ay2, bx1, by1), side(ax1, ay1, ax2, ay2, bx2, by2)
    d3, d4 = side(bx1, by1, bx2, by2, ax1, ay1), side(bx1, by1, bx2, by2, ax2, ay2)
    if d1 * d2 < 0 and d3 * d4 < 0:
        return 0.0
    return min(
        _point_to_segment(ax1, ay1, *b),
        _point_to_segment(ax2, ay2, *b),
        _point_to_segment(bx1, by1, *a),
        _point_to_segment(bx2, by2, *a),
    )


def test_obstacle_maze_has_angled_obstacles_and_corridors_of_0_35_m() -> None:
    world = load_world("obstacle_maze")
    assert {"ir_scout", "crowbot"} <= set(world.robots)
    width, depth = world.bounds[2] - world.bounds[0], world.bounds[3] - world.bounds[1]
    assert (width, depth) == (3.0, 2.5)
    yaws = np.degrees(world.boxes[:, 4]) % 90
    assert ((yaws >= 30) & (yaws <= 60)).sum() >= 3  # crates a narrow IR beam grazes
    angles = np.degrees(np.arctan2(*(world.segments[:, 2:] - world.segments[:, :2]).T[::-1])) % 90
    assert ((angles > 20) & (angles < 70)).sum() >= 4 + 3 * 4  # baffles plus the crates' edges
    # Walls come first in `segments`, then the four edges of each box: group them into obstacles.
    n_walls = len(world.segments) - 4 * len(world.boxes)
    obstacles = [[i] for i in range(n_walls)]
    obstacles += [
        list(range(n_walls + 4 * k, n_walls + 4 * k + 4)) for k in range(len(world.boxes))
    ]
    narrowest = math.inf
    for first, second in itertools.combinations(obstacles, 2):
        gap = min(_segment_gap(world.segments[i], world.segments[j]) for i in first for j in second)
        if gap > 1e-9:  # obstacles that touch (a baffle on the enclosure) form one surface
            narrowest = min(narrowest, gap)
    assert 0.35 <= narrowest < 0.5


def _free_path(free: np.ndarray, start: tuple[int, int], goal: tuple[int, int]) -> bool:
    """Breadth-first search over 4-connected True cells, (row, column) indices."""
    if not (free[start] and free[goal]):
        return False
    seen = np.zeros_like(free, dtype=bool)
    seen[start] = True
    queue = deque([start])
    while queue:
        row, col = queue.popleft()
        if (row, col) == goal:
            return True
        for nr, nc in ((row + 1, col), (row - 1, col), (row, col + 1), (row, col - 1)):
            inside = 0 <= nr < free.shape[0] and 0 <= nc < free.shape[1]
            if inside and free[nr, nc] and not seen[nr, nc]:
                seen[nr, nc] = True
                queue.append((nr, nc))
    return False


def _cell(grid: GridMap, x: float, y: float) -> tuple[int, int]:
    assert grid.origin_yaw == 0.0
    return int((y - grid.origin_y) // grid.resolution), int((x - grid.origin_x) // grid.resolution)


def _inflate(occupied: np.ndarray, cells: int) -> np.ndarray:
    """Grow occupied cells by `cells` in every direction (a square robot footprint)."""
    grown = occupied.copy()
    for dr in range(-cells, cells + 1):
        for dc in range(-cells, cells + 1):
            grown |= np.roll(np.roll(occupied, dr, axis=0), dc, axis=1)
    return grown


def test_obstacle_maze_is_passable_for_the_ir_scout() -> None:
    world = load_world("obstacle_maze")
    resolution = 0.02  # [m]
    shape = (round(2.5 / resolution), round(3.0 / resolution))
    grid = rasterize(
        world.segments,
        world.circles,
        world.boxes,
        world.bounds,
        resolution,
        (0.0, 0.0, 0.0),
        shape[1],
        shape[0],
    )
    free = ~_inflate(grid != 0, cells=4)  # a 12.2 cm robot plus margin: 0.08 m each side
    cells = GridMap(resolution, 0.0, 0.0, 0.0, shape[1], shape[0], grid)
    start, goal = world.spawn("start"), world.spawn("far_corner")
    assert _free_path(free, _cell(cells, start.x, start.y), _cell(cells, goal.x, goal.y))


def test_crop_rows_match_the_paper_field() -> None:
    world = load_world("crop_rows")
    plants = world.circles[np.array(world.circle_kind) == "plant"]
    assert plants[:, 2].min() >= 0.05 and plants[:, 2].max() <= 0.08
    # Rows: plants whose y lie within 0.1 m of each other.
    row_ys = np.sort(plants[:, 1])
    splits = np.flatnonzero(np.diff(row_ys) > 0.1) + 1
    rows = [plants[np.abs(plants[:, 1] - np.median(ys)) < 0.1] for ys in np.split(row_ys, splits)]
    assert len(rows) >= 3
    centres = [float(np.median(row[:, 1])) for row in rows]
    np.testing.assert_allclose(np.diff(centres), 0.8, atol=0.03)
    has_gap = False
    for row in rows:
        xs = np.sort(row[:, 0])
        assert 4.0 <= xs[-1] - xs[0] <= 5.0
        spacing = np.diff(xs)
        nominal = float(np.median(spacing))
        assert 0.15 <= nominal <= 0.25
        has_gap |= bool((spacing > 1.5 * nominal).any())
        # Headland: open ground of at least 1.2 m beyond both ends of every row.
        assert xs[0] - row[:, 2].max() - world.bounds[0] >= 1.2
        assert world.bounds[2] - (xs[-1] + row[:, 2].max()) >= 1.2
    assert has_gap
    # The start: in the first lane, 0.4 m right of the row on its left, heading along the rows.
    start = world.spawn("start")
    assert start.name == "start" and math.cos(start.yaw) > math.cos(math.radians(5))
    left_row = min((c for c in centres if c > start.y), key=lambda c: c - start.y)
    assert left_row - start.y == pytest.approx(0.4, abs=0.03)
    assert left_row == pytest.approx(centres[1], abs=1e-9)  # between the first two rows
    first_plant_x = min(row[:, 0].min() for row in rows)
    assert start.x <= first_plant_x + 0.2


def test_office_has_low_and_tall_furniture_and_a_post() -> None:
    world = load_world("office")
    width, depth = world.bounds[2] - world.bounds[0], world.bounds[3] - world.bounds[1]
    assert (width, depth) == (8.0, 6.0)
    heights = world.boxes[:, 5]
    slice_height = 0.45  # [m] the depth camera's laser-scan slice
    assert (heights < slice_height).sum() >= 2 and (heights >= 0.75).sum() >= 3
    assert "post" in world.circle_kind
    assert len(world.spawns) >= 3


def test_office_map_matches_the_geometry() -> None:
    world = load_world("office")
    grid = world.grid_map
    assert grid is not None and grid.resolution == 0.05
    assert grid.data.shape == (grid.height, grid.width) and grid.data.dtype == np.int8
    assert set(np.unique(grid.data).tolist()) == {-1, 0, 100}
    assert grid.data[0, 0] == -1  # the ring outside the floor is unknown
    for x1, y1, x2, y2 in world.segments:
        for t in np.linspace(0.0, 1.0, 25):
            x, y = x1 + t * (x2 - x1), y1 + t * (y2 - y1)
            row, col = _cell(grid, x, y)
            if world.bounds[0] < x < world.bounds[2] and world.bounds[1] < y < world.bounds[3]:
                assert grid.data[row, col] == 100, (x, y)
    for bx, by, *_ in world.boxes:
        assert grid.data[_cell(grid, bx, by)] == 100  # desks are solid on the map
    for spawn in world.spawns:
        assert grid.data[_cell(grid, spawn.x, spawn.y)] == 0, spawn.name
    assert 0.3 < (grid.data == 0).mean() < 0.9


def test_office_rooms_connect_through_0_8_m_doors() -> None:
    world = load_world("office")
    grid = world.grid_map
    assert grid is not None
    # Inflated by 0.15 m the free space still joins every room: the doors fit a TurtleBot.
    free = ~_inflate(grid.data != 0, cells=3)
    start = _cell(grid, world.spawn("start").x, world.spawn("start").y)
    for name in ("corridor", "room_b", "room_d"):
        spawn = world.spawn(name)
        assert _free_path(free, start, _cell(grid, spawn.x, spawn.y)), name


def test_office_without_doors_is_cut_into_rooms() -> None:
    data = _file_data("office")
    # Close the corridor's south wall across both doorways: the lab and office are shut in.
    data["walls"].append({"x1": 0.0, "y1": 2.5, "x2": 8.0, "y2": 2.5, "height": 2.0})
    world = parse_world(data, "office.toml")
    grid = world.grid_map
    assert grid is not None
    free = grid.data == 0
    start = _cell(grid, world.spawn("start").x, world.spawn("start").y)
    assert not _free_path(free, start, _cell(grid, *_xy(world, "corridor")))
    assert not _free_path(free, start, _cell(grid, *_xy(world, "room_d")))
    corridor = _cell(grid, *_xy(world, "corridor"))
    assert _free_path(free, corridor, _cell(grid, *_xy(world, "room_d")))  # north doors open


def _xy(world: World, name: str) -> tuple[float, float]:
    spawn = world.spawn(name)
    return spawn.x, spawn.y


def test_rasterized_diagonal_wall_is_a_closed_barrier() -> None:
    """A thin wall at 45 deg must not leave a corner-to-corner leak in a 4-connected grid."""
    segments = np.array([[0.0, 0.0, 1.0, 1.0]])
    grid = rasterize(
        segments,
        np.zeros((0, 3)),
        np.zeros((0, 6)),
        (0.0, 0.0, 1.0, 1.0),
        0.05,
        (0.0, 0.0, 0.0),
        20,
        20,
    )
    assert not _free_path(grid == 0, (0, 19), (19, 0))
    assert _free_path(grid == 0, (0, 19), (0, 5))


def test_rasterize_marks_cells_outside_bounds_unknown_and_follows_a_rotated_origin() -> None:
    circles = np.array([[0.25, 0.75, 0.05]])
    none = np.zeros((0, 4))
    grid = rasterize(
        none, circles, np.zeros((0, 6)), (0.0, 0.0, 1.0, 1.0), 0.1, (0.0, 0.0, 0.0), 12, 10
    )
    assert grid[7, 2] == 100 and grid[2, 7] == 0
    assert (grid[:, 10:] == -1).all() and (grid[:, :10] != -1).all()
    # Origin turned 90 deg: map +u is world +y, map +v is world -x.
    behind = np.array([[-0.25, 0.75, 0.05]])  # u = 0.75, v = 0.25 in the turned map
    turned = rasterize(
        none, behind, np.zeros((0, 6)), (-1.0, 0.0, 1.0, 1.0), 0.1, (0.0, 0.0, math.pi / 2), 10, 10
    )
    assert turned[2, 7] == 100 and turned[7, 2] == 0
