"""Worlds built directly from shapes (no world files) and sensing contexts in them, for the
simulator tests."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from server.sim.obstacles import Obstacles
from server.sim.sensors.base import SenseContext
from server.sim.state import RobotState
from server.sim.world import Spawn, World


def make_world(
    segments: Sequence[tuple[float, float, float, float]] = (),
    segment_height: float | Sequence[float] = 2.0,
    circles: Sequence[tuple[float, float, float]] = (),
    circle_height: float = 1.0,
) -> World:
    """A 40 m x 40 m world of wall `segments` (x1, y1, x2, y2) and cylinder `circles`
    (cx, cy, radius) [m]; `segment_height` [m] is one height for every wall or one per wall."""
    segment_array = np.asarray(segments, dtype=np.float64).reshape(-1, 4)
    circle_array = np.asarray(circles, dtype=np.float64).reshape(-1, 3)
    return World(
        id="test",
        title="test",
        description="",
        segments=segment_array,
        segment_height=np.broadcast_to(segment_height, len(segment_array)).astype(float),
        circles=circle_array,
        circle_height=np.full(len(circle_array), circle_height),
        tape_segments=np.zeros((0, 4)),
        tape_width=np.zeros(0),
        tape_darkness=np.zeros(0),
        lights=(),
        spawns=(Spawn(name="start", x=0.0, y=0.0, yaw=0.0),),
        bounds=(-20.0, -20.0, 20.0, 20.0),
        ambient_light=0.1,
        floor_reflectance=0.5,
        grid_map=None,
        robots=(),
    )


def make_context(
    world: World, state: RobotState | None = None, time_s: float = 0.0
) -> SenseContext:
    """What a sensor sees in `world`: the robot in `state` (at rest at the origin by default)."""
    return SenseContext(
        world=world,
        obstacles=Obstacles(world),
        state=state if state is not None else RobotState(),
        time_s=time_s,
        lights=(),
    )
