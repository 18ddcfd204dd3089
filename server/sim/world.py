"""Worlds: declarative TOML files, validated on load, compiled to numpy arrays for the sensors.

INTERFACE STUB (the loader, validation and registry are being written; the compiled shapes below
are the contract the physics and sensors code against).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


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
