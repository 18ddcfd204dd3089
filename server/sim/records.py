"""What a simulation hands out: the messages its sensors published, the events a run may
count, and snapshots for drawing. Plain frozen records, defined once (server/sim/simulation.py
makes them; runs, the 3D view and tests read them)."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

import numpy as np

from server.sim.state import Pose2D
from server.sim.world import LightSource


@dataclass(frozen=True, slots=True)
class Published:
    """A message a sensor topic published at simulated time `time_s` [s]."""

    topic: str
    time_s: float
    message: object


class EventKind(StrEnum):
    CONTACT_BEGAN = "contact_began"
    CONTACT_ENDED = "contact_ended"
    LEFT_BOUNDS = "left_bounds"
    ENTERED_BOUNDS = "entered_bounds"


@dataclass(frozen=True, slots=True)
class SimEvent:
    """Something a run may want to count or show, at `time_s` [s], the robot at x, y [m]."""

    kind: EventKind
    time_s: float
    x: float
    y: float


@dataclass(frozen=True, slots=True)
class Scene:
    """A snapshot for drawing: the true pose, actuator states, light positions, and the latest
    message on every topic (the 3D view draws rays from those)."""

    time_s: float
    robot_id: str
    world_id: str
    pose: Pose2D
    leds_rgb: tuple[int, int, int]
    buzzer_on: bool
    servo_angle_deg: float
    in_contact: bool
    lights: tuple[LightSource, ...]
    latest: dict[str, object]
    rays: dict[str, np.ndarray]  # topic -> (K, 4) world segments of what the sensor measured
