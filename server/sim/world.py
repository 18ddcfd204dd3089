"""Worlds: declarative TOML files, validated on load, compiled to numpy arrays for the sensors.

A world is `server/sim/worlds/<id>.toml` (the format and its checks live in
`server.sim.world_file`). `load_world(id)` reads, checks and compiles it once and caches the
immutable `World` (its arrays are read-only, so runs can share it);
`server.sim.checks.check_world` is the validator the tests run over every registered world.
Pure: the only I/O is reading the packaged world files.
"""

from __future__ import annotations

import functools
import math
import os
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from typing import Any

import numpy as np

from server.sim.geometry import distance_to_nearest, segment_arrays
from server.sim.world_file import (
    KNOWN_ROBOT_IDS,
    MAP_CELL_CHARS,
    WorldError,
    WorldSpec,
    parse_world_spec,
)

__all__ = [
    "KNOWN_ROBOT_IDS",
    "GridMap",
    "LightSource",
    "Spawn",
    "World",
    "WorldError",
    "load_world",
    "load_world_file",
    "parse_world",
    "world_ids",
]

_WORLDS_PACKAGE = "server.sim.worlds"
MAP_FREE, MAP_OCCUPIED, MAP_UNKNOWN = 0, 100, -1  # nav_msgs/OccupancyGrid cell values


@dataclass(frozen=True, slots=True)
class LightSource:
    """A point light: position [m], intensity [relative, 1.0 = a flashlight at 0.3 m saturates the
    CrowBot's light sensor], movable by the student/instructor during a run."""

    name: str
    x: float
    y: float
    z: float
    intensity: float
    movable: bool


@dataclass(frozen=True, slots=True)
class Spawn:
    """A named start pose: x, y [m], yaw [rad]."""

    name: str
    x: float
    y: float
    yaw: float


@dataclass(frozen=True, slots=True)
class GridMap:
    """An occupancy grid as nav_msgs/OccupancyGrid holds it: row-major int8 cells (0 free, 100
    occupied, -1 unknown), `resolution` [m/cell], `origin` the world pose (x, y [m], yaw [rad]) of
    cell (0, 0)'s corner."""

    resolution: float
    origin_x: float
    origin_y: float
    origin_yaw: float
    width: int
    height: int
    data: np.ndarray  # shape (height, width), dtype int8


@dataclass(frozen=True, slots=True)
class World:
    """A compiled world, immutable. All geometry in the world frame, metres.

    - `segments`: (N, 4) float64 rows (x1, y1, x2, y2): walls and the four edges of every box;
      the thin solid surfaces rays and the robot body hit.
    - `segment_height`: (N,) float64 [m] height of each segment's wall/box (a low box is under a
      depth camera's slice at 0.45 m).
    - `circles`: (M, 3) float64 rows (cx, cy, radius): cylinders (plants, posts).
    - `circle_height`: (M,) float64 [m].
    - `tape_segments`: (T, 4) float64 centre-line segments of floor tape; `tape_width` (T,) [m];
      `tape_darkness` (T,) in [0, 1] (1 = black tape).
    - `bounds`: (min_x, min_y, max_x, max_y) [m]; leaving it counts as out of bounds.
    - `ambient_light`: [0, 1] fraction of a light sensor's full scale from room light.
    - `floor_reflectance`: [0, 1] how bright the bare floor is to the line sensors.
    - `spawns`: named start poses; the first is the default.
    - `circle_kind`: (M,) "plant" or "post" per circle (empty for hand-built worlds).
    - `boxes`: (K, 6) float64 rows (cx, cy, width, depth, yaw [rad], height [m]): the solid boxes
      whose edges are in `segments`, for drawing and inside-tests.
    """

    id: str
    title: str
    description: str
    segments: np.ndarray
    segment_height: np.ndarray
    circles: np.ndarray
    circle_height: np.ndarray
    tape_segments: np.ndarray
    tape_width: np.ndarray
    tape_darkness: np.ndarray
    lights: tuple[LightSource, ...]
    spawns: tuple[Spawn, ...]
    bounds: tuple[float, float, float, float]
    ambient_light: float
    floor_reflectance: float
    grid_map: GridMap | None
    robots: tuple[str, ...]  # robot ids that make sense in this world (the registry checks them)
    circle_kind: tuple[str, ...] = ()
    boxes: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))

    def spawn(self, name: str | None = None) -> Spawn:
        """The spawn called `name`, or the default (first) one."""
        if name is None:
            return self.spawns[0]
        for spawn in self.spawns:
            if spawn.name == name:
                return spawn
        valid = ", ".join(s.name for s in self.spawns)
        raise WorldError(f"world '{self.id}' has no spawn '{name}'; choose one of: {valid}")

    def clearance(self, x: float, y: float) -> float:
        """Distance [m] from (x, y) to the nearest wall, box edge or cylinder surface; negative
        inside a box or cylinder, inf in an empty world. A disc robot of radius r fits if >= r."""
        point = np.array([x, y], dtype=float)
        nearest = distance_to_nearest(
            point, segment_arrays(self.segments), self.circles[:, :2], self.circles[:, 2]
        )
        for cx, cy, width, depth, yaw, _height in self.boxes:
            c, s = math.cos(yaw), math.sin(yaw)
            u, v = c * (x - cx) + s * (y - cy), -s * (x - cx) + c * (y - cy)
            inside = min(width / 2 - abs(u), depth / 2 - abs(v))
            if inside > 0:
                nearest = min(nearest, -inside)
        return nearest

    def in_bounds(self, x: float, y: float, margin_m: float = 0.0) -> bool:
        """Whether (x, y) [m] lies within `bounds` grown by `margin_m` on every side (edges
        included)."""
        min_x, min_y, max_x, max_y = self.bounds
        return (
            min_x - margin_m <= x <= max_x + margin_m and min_y - margin_m <= y <= max_y + margin_m
        )


def rasterize(
    segments: np.ndarray,
    circles: np.ndarray,
    boxes: np.ndarray,
    bounds: tuple[float, float, float, float],
    resolution: float,
    origin: tuple[float, float, float],
    width: int,
    height: int,
) -> np.ndarray:
    """An occupancy grid (height, width) int8 of the geometry: 100 where a wall, box edge or
    cylinder touches the cell's square or the centre is inside a box (a desk is solid on a map),
    -1 where the cell centre is outside `bounds`, else 0.

    Touching the square (not only passing near the centre) keeps a thin diagonal wall a closed
    barrier in the grid, so a planner cannot slip through it corner to corner.
    """
    ox, oy, oyaw = origin
    c, s = math.cos(oyaw), math.sin(oyaw)
    half = resolution / 2

    def to_map(xy: np.ndarray) -> np.ndarray:  # world (..., 2) -> map frame, metres
        dx, dy = xy[..., 0] - ox, xy[..., 1] - oy
        return np.stack([c * dx + s * dy, -s * dx + c * dy], axis=-1)

    grid = np.zeros((height, width), dtype=np.int8)

    def window(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        i0, j0 = np.floor(lo / resolution).astype(int) - 1
        i1, j1 = np.floor(hi / resolution).astype(int) + 1
        i0, j0, i1, j1 = max(i0, 0), max(j0, 0), min(i1, width - 1), min(j1, height - 1)
        if i0 > i1 or j0 > j1:
            return None
        return np.meshgrid(np.arange(i0, i1 + 1), np.arange(j0, j1 + 1))

    for x1, y1, x2, y2 in segments:
        p, q = to_map(np.array([x1, y1])), to_map(np.array([x2, y2]))
        cells = window(np.minimum(p, q), np.maximum(p, q))
        if cells is None:
            continue
        ii, jj = cells
        cx, cy = (ii + 0.5) * resolution, (jj + 0.5) * resolution
        nx, ny = -(q[1] - p[1]), q[0] - p[0]  # separating-axis test, segment vs cell square
        touch = (
            (np.minimum(p[0], q[0]) <= cx + half)
            & (np.maximum(p[0], q[0]) >= cx - half)
            & (np.minimum(p[1], q[1]) <= cy + half)
            & (np.maximum(p[1], q[1]) >= cy - half)
            & (np.abs(nx * (cx - p[0]) + ny * (cy - p[1])) <= half * (abs(nx) + abs(ny)) + 1e-12)
        )
        grid[jj[touch], ii[touch]] = MAP_OCCUPIED
    for x, y, radius in circles:
        centre = to_map(np.array([x, y]))
        cells = window(centre - radius, centre + radius)
        if cells is None:
            continue
        ii, jj = cells
        dx = np.maximum(np.abs((ii + 0.5) * resolution - centre[0]) - half, 0.0)
        dy = np.maximum(np.abs((jj + 0.5) * resolution - centre[1]) - half, 0.0)
        touch = np.hypot(dx, dy) <= radius
        grid[jj[touch], ii[touch]] = MAP_OCCUPIED
    ii, jj = np.meshgrid(np.arange(width), np.arange(height))
    u, v = (ii + 0.5) * resolution, (jj + 0.5) * resolution
    wx, wy = ox + c * u - s * v, oy + s * u + c * v
    for bx, by, box_width, box_depth, box_yaw, _height in boxes:
        bc, bs = math.cos(box_yaw), math.sin(box_yaw)
        along, across = bc * (wx - bx) + bs * (wy - by), -bs * (wx - bx) + bc * (wy - by)
        grid[(np.abs(along) <= box_width / 2) & (np.abs(across) <= box_depth / 2)] = MAP_OCCUPIED
    outside = (wx < bounds[0]) | (wx > bounds[2]) | (wy < bounds[1]) | (wy > bounds[3])
    grid[outside] = MAP_UNKNOWN
    return grid


def _frozen(rows: list, columns: int) -> np.ndarray:
    array = np.array(rows, dtype=np.float64).reshape(-1, columns)
    array.flags.writeable = False
    return array


def compile_world(spec: WorldSpec) -> World:
    """Turn a checked `WorldSpec` into the immutable `World` the simulator reads."""
    segments = _frozen([s[:4] for s in spec.segments], 4)
    circles = _frozen([c[:3] for c in spec.circles], 3)
    boxes = _frozen(spec.boxes, 6)
    grid_map = None
    if spec.map is not None:
        m = spec.map
        if m["rows"] is not None:
            cells = [[MAP_CELL_CHARS[ch] for ch in row] for row in reversed(m["rows"])]
            data = np.array(cells, dtype=np.int8)
        else:
            args = (spec.bounds, m["resolution"], m["origin"], m["width"], m["height"])
            data = rasterize(segments, circles, boxes, *args)
        data.flags.writeable = False
        grid_map = GridMap(m["resolution"], *m["origin"], m["width"], m["height"], data)
    return World(
        id=spec.id,
        title=spec.title,
        description=spec.description,
        segments=segments,
        segment_height=_frozen([s[4] for s in spec.segments], 1).ravel(),
        circles=circles,
        circle_height=_frozen([c[3] for c in spec.circles], 1).ravel(),
        tape_segments=_frozen([t[:4] for t in spec.tape], 4),
        tape_width=_frozen([t[4] for t in spec.tape], 1).ravel(),
        tape_darkness=_frozen([t[5] for t in spec.tape], 1).ravel(),
        lights=tuple(LightSource(*light) for light in spec.lights),
        spawns=tuple(Spawn(*spawn) for spawn in spec.spawns),
        bounds=spec.bounds,
        ambient_light=spec.ambient_light,
        floor_reflectance=spec.floor_reflectance,
        grid_map=grid_map,
        robots=spec.robots,
        circle_kind=tuple(c[4] for c in spec.circles),
        boxes=boxes,
    )


def parse_world(
    data: dict[str, Any], source: str = "<dict>", known_robot_ids: tuple[str, ...] = KNOWN_ROBOT_IDS
) -> World:
    """Check and compile a world file's dict as `tomllib` reads it; `source` names it in errors."""
    return compile_world(parse_world_spec(data, source, known_robot_ids))


def _parse_toml(text: bytes, file_name: str) -> World:
    try:
        data = tomllib.loads(text.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise WorldError(f"world file {file_name}: not valid TOML: {error}") from None
    stem = file_name.rsplit("/", 1)[-1].removesuffix(".toml")
    if "id" in data and data["id"] != stem:
        raise WorldError(
            f"world file {file_name}: id {data['id']!r} does not match the file name; "
            f"set id = {stem!r} or rename the file to {data['id']}.toml"
        )
    return parse_world(data, file_name)


def load_world_file(path: str | os.PathLike[str]) -> World:
    """Read, check and compile one world file; its `id` must equal the file name's stem."""
    with open(path, "rb") as handle:
        return _parse_toml(handle.read(), os.fspath(path))


def world_ids() -> tuple[str, ...]:
    """The ids of the packaged worlds (`server/sim/worlds/*.toml`), sorted."""
    files = resources.files(_WORLDS_PACKAGE).iterdir()
    return tuple(sorted(f.name.removesuffix(".toml") for f in files if f.name.endswith(".toml")))


@functools.cache
def load_world(world_id: str) -> World:
    """The packaged world `world_id`, checked and compiled once, then shared (it is immutable)."""
    valid = world_ids()
    if world_id not in valid:
        raise WorldError(f"unknown world {world_id!r} (valid ids: {', '.join(valid)})")
    resource = resources.files(_WORLDS_PACKAGE).joinpath(f"{world_id}.toml")
    return _parse_toml(resource.read_bytes(), f"{world_id}.toml")
