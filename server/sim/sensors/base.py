"""The contract every simulated sensor follows.

A sensor is a pure function of the world, the robot state, the simulated time and its own seeded
random generator: `sample()` builds one message. The simulation calls it when the sensor's topic
is due (at `rate_hz`), passing a generator that belongs to this sensor alone, so reading one
topic more or less often never changes another topic's noise.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

if TYPE_CHECKING:
    from server.sim.obstacles import Obstacles
    from server.sim.state import RobotState
    from server.sim.world import LightSource, World


@dataclass(frozen=True, slots=True)
class SenseContext:
    """What a sensor may look at when it samples: the compiled world, the robot state, the
    simulated time [s] since reset, and the light sources where they are now (lights can be
    moved during a run, so they live here rather than in the immutable `World`), and the world's
    solid surfaces prepared for ray casts (`obstacles`)."""

    world: World
    obstacles: Obstacles
    state: RobotState
    time_s: float
    lights: tuple[LightSource, ...]


class Sensor(Protocol):
    """A simulated sensor: it publishes `msg_type` messages at `rate_hz` [Hz], the first one at
    `phase_s` [s] after reset (rangers fired one after another use different phases)."""

    msg_type: type
    rate_hz: float
    phase_s: float

    def reset(self) -> None:
        """Forget internal state (a drifting bias, a previous reading) before a new episode."""
        ...

    def sample(self, ctx: SenseContext, rng: np.random.Generator) -> object:
        """Return one message of `msg_type` for the state in `ctx`."""
        ...


class DrawsRays(Protocol):
    """A sensor that can show what it measured: `rays(ctx, message)` returns world-frame line
    segments (K, 4) rows (x1, y1, x2, y2) [m] for the 3D view (a beam, a cone's edges, scan
    points as short rays)."""

    def rays(self, ctx: SenseContext, message: object) -> np.ndarray: ...


def fan(
    origin_x: float, origin_y: float, headings_rad: np.ndarray, lengths_m: np.ndarray
) -> np.ndarray:
    """Rays from one origin: (K, 4) segments along `headings_rad`, each `lengths_m` long."""
    headings = np.asarray(headings_rad, dtype=np.float64)
    lengths = np.broadcast_to(np.asarray(lengths_m, dtype=np.float64), headings.shape)
    return np.stack(
        [
            np.full(headings.shape, origin_x),
            np.full(headings.shape, origin_y),
            origin_x + lengths * np.cos(headings),
            origin_y + lengths * np.sin(headings),
        ],
        axis=1,
    )


class StatelessSensor:
    """Mixin for sensors without internal state: phase 0, nothing to reset."""

    phase_s: float = 0.0

    def reset(self) -> None:
        return None
