"""Every packaged world builds into a scene, with as many walls and boxes as its file declares,
the map the right way up, tape and cylinders all there."""

from __future__ import annotations

import tomllib
from importlib import resources

import numpy as np
import pytest

from server.sim.world import MAP_OCCUPIED, load_world, world_ids
from server.viz.world_scene import (
    MAP_OCCUPIED_RGBA,
    box_slabs,
    draw_world,
    map_image,
    tape_mesh,
    wall_count,
    wall_slabs,
)


def world_file(world_id: str) -> dict:
    text = resources.files("server.sim.worlds").joinpath(f"{world_id}.toml").read_text()
    return tomllib.loads(text)


@pytest.mark.parametrize("world_id", world_ids())
def test_every_world_builds_with_the_walls_and_boxes_of_its_file(world_id, viser_server):
    world = load_world(world_id)
    declared = world_file(world_id)
    nodes = draw_world(viser_server.scene, world)
    assert nodes.walls == len(declared.get("walls", [])) == wall_count(world)
    assert nodes.boxes == len(declared.get("boxes", []))
    assert nodes.cylinders == len(world.circles)
    assert nodes.tape_chords == len(world.tape_segments)
    assert nodes.has_map == (world.grid_map is not None)
    for name in nodes.names:
        assert viser_server.scene.get_handle_by_name(name) is not None, name


def test_walls_stand_on_their_segments_at_their_height():
    world = load_world("light_arena")
    slabs = wall_slabs(world)
    x1, y1, x2, y2 = world.segments[0]
    assert slabs.centres[0] == pytest.approx([(x1 + x2) / 2, (y1 + y2) / 2, 0.05])
    assert slabs.sizes[0, 0] >= np.hypot(x2 - x1, y2 - y1)
    assert slabs.sizes[0, 2] == pytest.approx(world.segment_height[0])
    assert slabs.yaws[0] == pytest.approx(np.arctan2(y2 - y1, x2 - x1))


def test_boxes_keep_their_size_and_yaw():
    world = load_world("office")
    slabs = box_slabs(world)
    assert len(slabs) == len(world.boxes) == 9
    assert slabs.sizes == pytest.approx(world.boxes[:, [2, 3, 5]])
    assert slabs.yaws == pytest.approx(world.boxes[:, 4])
    assert slabs.centres[:, 2] == pytest.approx(world.boxes[:, 5] / 2)


def test_the_map_image_keeps_the_grids_row_order():
    grid = load_world("office").grid_map
    image = map_image(grid)
    assert image.shape == (grid.height, grid.width, 4)
    dark = (image[..., :4] == MAP_OCCUPIED_RGBA).all(axis=2)
    assert np.array_equal(dark, grid.data >= MAP_OCCUPIED)  # row 0 at y = origin, viser's -y
    assert not dark[0].any() and (image[0, :, 3] > 0).all()  # the unknown margin


def test_tape_quads_are_as_wide_as_the_tape():
    world = load_world("line_track")
    (grey, (vertices, faces)), *_ = tape_mesh(world).items()
    assert grey == round(255 * (1 - round(float(world.tape_darkness[0]), 1)))
    assert len(faces) == 2 * len(world.tape_segments)
    corners = vertices[:4, :2]
    width = np.hypot(*(corners[2] - corners[1]))
    assert width == pytest.approx(world.tape_width[0], rel=1e-5)
