"""The world file format: every mistake is refused with a message naming the field and the fix."""

from __future__ import annotations

import copy
import math
from collections.abc import Callable

import numpy as np
import pytest

from server.sim.world import World, WorldError, load_world_file, parse_world


def tiny() -> dict:
    """A small valid world using every section; each bad case below breaks one thing in it."""
    return {
        "id": "tiny",
        "title": "Tiny",
        "robots": ["crowbot"],
        "bounds": {"min_x": 0.0, "min_y": 0.0, "max_x": 2.0, "max_y": 1.0},
        "spawns": [{"name": "start", "x": 0.5, "y": 0.5, "yaw_deg": 90.0}],
        "walls": [{"x1": 1.5, "y1": 0.0, "x2": 1.5, "y2": 1.0}],
        "boxes": [{"x": 1.0, "y": 0.2, "width": 0.2, "depth": 0.1, "yaw_deg": 30.0}],
        "cylinders": [{"x": 0.2, "y": 0.8, "radius": 0.05, "kind": "post"}],
        "plant_rows": [{"start": [0.1, 0.1], "end": [0.9, 0.1], "spacing": 0.2, "radius": 0.03}],
        "lights": [{"name": "lamp", "x": 1.0, "y": 0.9, "z": 0.1, "movable": True}],
        "tape": [{"points": [[0.2, 0.3], [0.8, 0.3], [0.8, 0.7]], "width": 0.025}],
        "map": {"resolution": 0.1, "source": "geometry"},
    }


def test_tiny_world_compiles_every_section() -> None:
    world = parse_world(tiny(), "tiny.toml")
    assert isinstance(world, World)
    assert world.segments.shape == (1 + 4, 4)  # the wall and the box's four edges
    assert world.segment_height.tolist() == [0.5] * 5  # the default height
    assert world.circles.shape == (1 + 5, 3)  # the post and plants at x = 0.1, 0.3, ..., 0.9
    assert world.circle_kind == ("post",) + ("plant",) * 5
    assert world.spawns[0].yaw == pytest.approx(math.pi / 2)  # degrees in the file, rad compiled
    assert world.lights[0].movable is True and world.lights[0].intensity == 1.0
    assert world.tape_segments.shape[1] == 4 and len(world.tape_segments) >= 2
    assert world.grid_map is not None and world.grid_map.data.shape == (10, 20)
    with pytest.raises(ValueError, match="read-only"):
        world.segments[0, 0] = 9.0


def _set(path: str, value: object) -> Callable[[dict], None]:
    """A mutation that sets data[a][i][b]... = value, for a path like 'walls.0.x2'."""

    def mutate(data: dict) -> None:
        *parents, last = [int(p) if p.isdigit() else p for p in path.split(".")]
        node = data
        for key in parents:
            node = node[key]
        node[last] = value

    return mutate


def _delete(path: str) -> Callable[[dict], None]:
    def mutate(data: dict) -> None:
        *parents, last = [int(p) if p.isdigit() else p for p in path.split(".")]
        node = data
        for key in parents:
            node = node[key]
        del node[last]

    return mutate


BAD_CASES = [
    (_set("walls.0.x2", "abc"), "walls[0].x2: expected a number in metres, got 'abc'"),
    (_set("plant_rows.0.spacing", -0.1), "plant_rows[0].spacing must be > 0 (got -0.1)"),
    (_set("walls.0.hieght", 0.3), "walls[0]: unknown key 'hieght' (valid: x1, y1, x2, y2, height)"),
    (_delete("walls.0.x2"), "walls[0]: missing required key 'x2'"),
    (_delete("bounds"), "missing required key 'bounds'"),
    (_delete("bounds.max_y"), "bounds: missing required key 'max_y'"),
    (_set("spawns.0.x", 2.5), "spawns[0] 'start' at (2.5, 0.5) is outside bounds"),
    (_set("robots", ["crowbott"]), "robots[0]: unknown robot id 'crowbott' (valid: crowbot, "),
    (_set("map.resolution", 0), "map.resolution must be > 0 (got 0)"),
    (_set("map.resolution", -0.05), "map.resolution must be > 0 (got -0.05)"),
    (_set("lights.0.z", math.nan), "lights[0].z must be a finite number (got nan)"),
    (_set("cylinders.0.radius", math.inf), "cylinders[0].radius must be a finite number"),
    (_set("walls.0.height", True), "walls[0].height: expected a number in metres, got true"),
    (_set("ambient_light", 1.5), "ambient_light must be <= 1 (got 1.5)"),
    (_set("cylinders.0.kind", "tree"), "cylinders[0].kind: expected one of plant, post"),
    (_set("plant_rows.0.gaps", [9]), "plant_rows[0].gaps[0] = 9 is past the row's last plant"),
    (_set("plant_rows.0.jitter", 0.15), "plant_rows[0].jitter must be < spacing / 2"),
    (
        lambda d: d["tape"][0].update(closed=True, points=[[0.2, 0.3], [0.8, 0.3]]),
        "tape[0]: a closed tape needs at least 3 points (got 2)",
    ),
    (_set("tape.0.points", [[0.2, 0.3]]), "tape[0].points: needs at least 2 entries"),
    (_set("tape.0.points", [[0.2, 0.3], "x"]), "tape[0].points[1]: expected a point [x, y]"),
    (_set("tape.0.corner_radius", 0.5), "tape[0].corner_radius 0.5 is too large"),
    (_set("map.rows", ["#."]), "map: give either source"),
    (_set("map", {"resolution": 0.1, "rows": ["#.", "..."]}), "map.rows: every row"),
    (_set("map", {"resolution": 0.1, "rows": ["#x"]}), "map.rows[0]: unknown cell 'x'"),
    (
        lambda d: d["spawns"].append({"name": "start", "x": 1.0, "y": 0.5}),
        "spawns[1]: name 'start' is used twice; rename one",
    ),
    (_set("colour", "red"), "unknown top-level key 'colour' (valid: id, title,"),
    (_set("walls", {"x1": 0.0}), "walls: expected an array of tables written [[walls]]"),
    (_set("bounds.max_x", -1.0), "bounds: min_x < max_x and min_y < max_y needed"),
    (
        lambda d: d["walls"][0].update(y2=0.0),
        "walls[0]: both ends are the same point; give it a length",
    ),
    (_set("id", "Office 2"), "id: 'Office 2' must be a lowercase identifier"),
    (_set("spawns", []), "spawns: add at least one [[spawns]]"),
]


@pytest.mark.parametrize(("mutate", "expected"), BAD_CASES)
def test_malformed_world_names_the_field(mutate: Callable[[dict], None], expected: str) -> None:
    data = copy.deepcopy(tiny())
    mutate(data)
    with pytest.raises(WorldError) as caught:
        parse_world(data, "tiny.toml")
    message = str(caught.value)
    assert expected in message
    # Once the id is readable it names the world; before that, the file.
    assert message.startswith("world 'tiny': ") or message.startswith("world file tiny.toml: ")


def test_every_bad_case_changes_something() -> None:
    """Guards the table: a mutation that leaves the world valid would make its case vacuous."""
    parse_world(tiny(), "tiny.toml")  # the base world itself is fine
    for mutate, _expected in BAD_CASES:
        data = copy.deepcopy(tiny())
        mutate(data)
        assert data != tiny()


def test_unknown_robot_ids_come_from_the_caller() -> None:
    data = tiny()
    data["robots"] = ["rover9"]
    world = parse_world(data, "tiny.toml", known_robot_ids=("rover9",))
    assert world.robots == ("rover9",)
    with pytest.raises(WorldError, match=r"unknown robot id 'rover9' \(valid: crowbot, crop_rover"):
        parse_world(data, "tiny.toml")


def test_id_must_match_the_file_name(tmp_path) -> None:
    path = tmp_path / "bar.toml"
    path.write_text(
        'id = "foo"\ntitle = "Foo"\nrobots = ["crowbot"]\n'
        "[bounds]\nmin_x = 0\nmin_y = 0\nmax_x = 1\nmax_y = 1\n"
        '[[spawns]]\nname = "s"\nx = 0.5\ny = 0.5\n'
    )
    with pytest.raises(WorldError, match=r"id 'foo' does not match the file name; set id = 'bar'"):
        load_world_file(path)
    path.rename(tmp_path / "foo.toml")
    assert load_world_file(tmp_path / "foo.toml").id == "foo"


def test_toml_syntax_errors_name_the_file(tmp_path) -> None:
    path = tmp_path / "broken.toml"
    path.write_text('id = "broken"\n[bounds\n')
    with pytest.raises(WorldError, match=r"broken\.toml: not valid TOML"):
        load_world_file(path)


def test_plant_jitter_is_fixed_by_the_seed() -> None:
    data = tiny()
    data["plant_rows"][0].update(jitter=0.02, seed=7)
    first, again = parse_world(data, "tiny.toml"), parse_world(data, "tiny.toml")
    np.testing.assert_array_equal(first.circles, again.circles)
    data["plant_rows"][0]["seed"] = 8
    assert not np.array_equal(first.circles, parse_world(data, "tiny.toml").circles)
    plants = first.circles[1:]
    assert np.abs(plants[:, 1] - 0.1).max() <= 0.02  # jitter stays within its bound
    assert np.abs(plants[:, 1] - 0.1).max() > 0.0


def test_plant_row_gaps_leave_plants_out() -> None:
    data = tiny()
    data["plant_rows"][0]["gaps"] = [1, 3]
    xs = parse_world(data, "tiny.toml").circles[1:, 0]
    np.testing.assert_allclose(xs, [0.1, 0.5, 0.9])


def test_rounded_tape_corner_is_an_arc_of_the_given_radius() -> None:
    data = tiny()
    data["tape"][0].update(corner_radius=0.2, max_segment=0.01)
    tape = parse_world(data, "tiny.toml").tape_segments
    lengths = np.hypot(*(tape[:, 2:] - tape[:, :2]).T)
    assert lengths.max() <= 0.01 + 1e-9
    # The corner at (0.8, 0.3) becomes a quarter circle centred at (0.6, 0.5).
    points = tape[:, :2]
    on_arc = points[(points[:, 0] > 0.6 + 1e-6) & (points[:, 1] < 0.5 - 1e-6)]
    assert len(on_arc) >= 5
    np.testing.assert_allclose(np.hypot(*(on_arc - [0.6, 0.5]).T), 0.2, atol=1e-9)
    np.testing.assert_allclose(tape[0, :2], [0.2, 0.3])  # open ends stay where they were
    np.testing.assert_allclose(tape[-1, 2:], [0.8, 0.7])


def test_inline_map_rows_are_written_top_row_first() -> None:
    data = tiny()
    data["map"] = {"resolution": 0.5, "origin": [0.0, 0.0, 0.0], "rows": ["#...", "..?."]}
    grid = parse_world(data, "tiny.toml").grid_map
    assert grid is not None and (grid.width, grid.height) == (4, 2)
    assert grid.data.dtype == np.int8
    assert grid.data[1].tolist() == [100, 0, 0, 0]  # the top row in the file has the larger y
    assert grid.data[0].tolist() == [0, 0, -1, 0]
