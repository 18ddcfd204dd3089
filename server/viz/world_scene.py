"""A world drawn in a viser scene: floor, walls, boxes, plants and posts, floor tape and, where the
world has one, its occupancy map laid on the floor (light sources are `lights.py`: they move).

The shapes come from the compiled `World` (server/sim/world.py), so the view shows exactly what
the simulator collides with and senses: walls are the first `len(segments) - 4 len(boxes)`
segments (the rest are box edges), boxes are `world.boxes`, cylinders `world.circles`.
Pure geometry first (`wall_slabs`, `box_slabs`, `tape_mesh`, `map_image`), testable without a
server; `draw_world` hands it to viser as a few batched meshes (one node per kind, not per wall).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from server.sim.world import MAP_OCCUPIED, MAP_UNKNOWN, GridMap, World
from server.viz.meshes import unit_box, unit_cylinder, yaw_wxyz, yaw_wxyzs

WALL_THICKNESS_M = 0.03  # [m] walls are lines to the simulator; drawn this thick to be seen
WALL_OPACITY = 0.5  # [1] see-through: a 2 m office wall would hide the robot behind it
FLOOR_MARGIN_M = 0.3  # [m] floor beyond the world's bounds, so the edge walls stand on it
FLOOR_THICKNESS_M = 0.01  # [m] top face at z = 0
MAP_LIFT_M = 0.002  # [m] above the floor, so the map does not flicker against it
TAPE_LIFT_M = 0.003  # [m] above the map
GRID_LIFT_M = 0.001  # [m] above the floor, below the map
GRID_CELLS_PER_SECTION = 5  # [-] a darker line every 5 cells
# Colours, RGB 0-255: a light floor with a darker grid, so dark tape and the map read on it and
# the robot (robot_drawing.py: saturated blue) stands out; walls a darker slate with shading.
FLOOR_RGB = (226, 224, 216)
GRID_CELL_RGB = (192, 190, 182)
GRID_SECTION_RGB = (150, 148, 140)
WALL_RGB = (104, 114, 132)
BOX_RGB = (168, 116, 70)
PLANT_RGB = (50, 140, 60)
POST_RGB = (110, 110, 118)
MAP_OCCUPIED_RGBA = (40, 40, 60, 150)
MAP_UNKNOWN_RGBA = (90, 90, 90, 70)


@dataclass(frozen=True, slots=True)
class Slabs:
    """Upright boxes standing on the floor: centres (N, 3) [m], sizes (N, 3) [m] along their own
    x, y, z, and yaws (N,) [rad]."""

    centres: np.ndarray
    sizes: np.ndarray
    yaws: np.ndarray

    def __len__(self) -> int:
        return len(self.yaws)


def wall_count(world: World) -> int:
    """How many of `world.segments` are walls (the rest are the four edges of each box)."""
    return len(world.segments) - 4 * len(world.boxes)


def wall_slabs(world: World) -> Slabs:
    walls = world.segments[: wall_count(world)]
    heights = world.segment_height[: wall_count(world)]
    x1, y1, x2, y2 = walls.T if len(walls) else np.zeros((4, 0))
    lengths = np.hypot(x2 - x1, y2 - y1) + WALL_THICKNESS_M  # closes the corners
    centres = np.column_stack([(x1 + x2) / 2, (y1 + y2) / 2, heights / 2])
    sizes = np.column_stack([lengths, np.full(len(walls), WALL_THICKNESS_M), heights])
    return Slabs(centres.reshape(-1, 3), sizes.reshape(-1, 3), np.arctan2(y2 - y1, x2 - x1))


def box_slabs(world: World) -> Slabs:
    boxes = world.boxes
    cx, cy, width, depth, yaw, height = boxes.T if len(boxes) else np.zeros((6, 0))
    centres = np.column_stack([cx, cy, height / 2]).reshape(-1, 3)
    return Slabs(centres, np.column_stack([width, depth, height]).reshape(-1, 3), yaw)


def cylinder_kinds(world: World) -> dict[str, np.ndarray]:
    """Kind ("plant", "post") -> indices into `world.circles` (a hand-built world without
    kinds has posts)."""
    kinds = np.array(world.circle_kind or ("post",) * len(world.circles))
    return {kind: np.flatnonzero(kinds == kind) for kind in dict.fromkeys(kinds.tolist())}


def tape_mesh(world: World) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Floor tape as flat quads (one per centre-line chord, its own width), grouped by darkness
    in tenths: grey level -> (vertices, faces)."""
    groups: dict[int, tuple[list, list]] = {}
    for (x1, y1, x2, y2), width, darkness in zip(
        world.tape_segments, world.tape_width, world.tape_darkness, strict=True
    ):
        length = np.hypot(x2 - x1, y2 - y1)
        if length == 0.0:
            continue
        # Half a width either side, and half a width past each end so chords overlap at bends.
        ux, uy = (x2 - x1) / length * width / 2, (y2 - y1) / length * width / 2
        corners = [
            (x1 - ux + uy, y1 - uy - ux),
            (x2 + ux + uy, y2 + uy - ux),
            (x2 + ux - uy, y2 + uy + ux),
            (x1 - ux - uy, y1 - uy + ux),
        ]
        grey = round(255 * (1.0 - round(float(darkness), 1)))
        vertices, faces = groups.setdefault(grey, ([], []))
        base = len(vertices)
        vertices += [(x, y, TAPE_LIFT_M) for x, y in corners]
        faces += [(base, base + 1, base + 2), (base, base + 2, base + 3)]
    return {
        grey: (np.array(v, dtype=np.float32), np.array(f, dtype=np.uint32))
        for grey, (v, f) in groups.items()
    }


def grid_cell_m(bounds: tuple[float, float, float, float]) -> float:
    """The floor grid's cell [m]: 0.1 m in a table-top arena, 0.5 m in a room (~20-40 cells
    across the world's larger side either way)."""
    min_x, min_y, max_x, max_y = bounds
    return 0.1 if max(max_x - min_x, max_y - min_y) <= 4.0 else 0.5


def map_image(grid: GridMap) -> np.ndarray:
    """The occupancy grid as an RGBA image (height, width, 4): free cells clear, occupied dark,
    unknown grey. Rows stay in the grid's order (row 0 at the map's origin, smallest y): viser
    lays an image's first row toward the node's -y (OpenCV's image axes, y down), which is where
    row 0 belongs; flipping it showed the office's desks mirrored about the corridor."""
    image = np.zeros((grid.height, grid.width, 4), dtype=np.uint8)
    image[grid.data >= MAP_OCCUPIED] = MAP_OCCUPIED_RGBA
    image[grid.data == MAP_UNKNOWN] = MAP_UNKNOWN_RGBA
    return image


@dataclass(frozen=True, slots=True)
class WorldNodes:
    """Names of the scene nodes `draw_world` made, and how many of each shape they hold."""

    names: tuple[str, ...]
    walls: int
    boxes: int
    cylinders: int
    tape_chords: int
    has_map: bool


def _draw_slabs(
    scene, name: str, slabs: Slabs, rgb: tuple[int, int, int], opacity: float | None = None
) -> None:
    vertices, faces = unit_box()
    scene.add_batched_meshes_simple(
        name,
        vertices,
        faces,
        batched_wxyzs=yaw_wxyzs(slabs.yaws),
        batched_positions=slabs.centres,
        batched_scales=slabs.sizes,
        batched_colors=rgb,
        flat_shading=True,
        lod="off",
        opacity=opacity,
    )


def draw_world(scene, world: World) -> WorldNodes:
    """Add `world` under /world in `scene` (a viser SceneApi); returns what was drawn."""
    scene.add_frame("/world", show_axes=False)
    names = []
    min_x, min_y, max_x, max_y = world.bounds
    size_x, size_y = max_x - min_x + 2 * FLOOR_MARGIN_M, max_y - min_y + 2 * FLOOR_MARGIN_M
    scene.add_box(
        "/world/floor",
        color=FLOOR_RGB,
        dimensions=(size_x, size_y, FLOOR_THICKNESS_M),
        position=((min_x + max_x) / 2, (min_y + max_y) / 2, -FLOOR_THICKNESS_M / 2),
        cast_shadow=False,
    )
    names.append("/world/floor")
    cell_m = grid_cell_m(world.bounds)
    scene.add_grid(
        "/world/grid",
        width=max_x - min_x,
        height=max_y - min_y,
        plane="xy",
        cell_size=cell_m,
        cell_color=GRID_CELL_RGB,
        section_size=GRID_CELLS_PER_SECTION * cell_m,
        section_color=GRID_SECTION_RGB,
        section_thickness=1.5,
        shadow_opacity=0.2,
        position=((min_x + max_x) / 2, (min_y + max_y) / 2, GRID_LIFT_M),
    )
    names.append("/world/grid")
    walls, boxes = wall_slabs(world), box_slabs(world)
    for name, slabs, rgb, opacity in (
        ("/world/walls", walls, WALL_RGB, WALL_OPACITY),
        ("/world/boxes", boxes, BOX_RGB, None),
    ):
        if len(slabs):
            _draw_slabs(scene, name, slabs, rgb, opacity)
            names.append(name)
    cylinder_vertices, cylinder_faces = unit_cylinder()
    for kind, indices in cylinder_kinds(world).items():
        circles, heights = world.circles[indices], world.circle_height[indices]
        scene.add_batched_meshes_simple(
            f"/world/{kind}s",
            cylinder_vertices,
            cylinder_faces,
            batched_wxyzs=yaw_wxyzs(np.zeros(len(indices))),
            batched_positions=np.column_stack([circles[:, :2], heights / 2]),
            batched_scales=np.column_stack([circles[:, 2], circles[:, 2], heights]),
            batched_colors=PLANT_RGB if kind == "plant" else POST_RGB,
            lod="off",
        )
        names.append(f"/world/{kind}s")
    tape = tape_mesh(world)
    for grey, (vertices, faces) in tape.items():
        scene.add_mesh_simple(
            f"/world/tape_{grey}", vertices, faces, color=(grey, grey, grey), side="double"
        )
        names.append(f"/world/tape_{grey}")
    grid = world.grid_map
    if grid is not None:
        width_m, height_m = grid.width * grid.resolution, grid.height * grid.resolution
        c, s = np.cos(grid.origin_yaw), np.sin(grid.origin_yaw)
        centre_x = grid.origin_x + c * width_m / 2 - s * height_m / 2
        centre_y = grid.origin_y + s * width_m / 2 + c * height_m / 2
        scene.add_image(
            "/world/map",
            map_image(grid),
            render_width=width_m,
            render_height=height_m,
            format="png",
            wxyz=yaw_wxyz(grid.origin_yaw),
            position=(centre_x, centre_y, MAP_LIFT_M),
            cast_shadow=False,
        )
        names.append("/world/map")
    return WorldNodes(
        names=tuple(names),
        walls=len(walls),
        boxes=len(boxes),
        cylinders=len(world.circles),
        tape_chords=sum(len(faces) // 2 for _, faces in tape.values()),
        has_map=grid is not None,
    )
