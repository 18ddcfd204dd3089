"""The robot a run drives: the `RobotBackend` protocol, which `Simulation` (server/sim) and
`HardwareRobot` (server/hardware/backend.py) both implement, so the run engine never asks which
one it has.

    backend.reset()                  -> messages published at time 0
    backend.step(dt_s)               -> messages published in the next dt_s [s] of run time
    backend.apply(topic, message)    a command (the safety layer sits inside a real robot's)
    backend.stop()                   zero velocity now (every end of a run calls it)

A real robot cannot press its own button, move the lab's lights or say where it truly is: those
calls raise `SimulationError` with a sentence there, and its `state.pose` stays at the origin.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol, runtime_checkable

if TYPE_CHECKING:
    from collections.abc import Callable

    from server.sim.robots.base import RobotModel, TopicSpec
    from server.sim.simulation import Published, SimEvent
    from server.sim.state import Pose2D, RobotState
    from server.sim.world import LightSource


class WorldView(Protocol):
    """What a run reads of the world it happens in (a simulated World, or a lab bench)."""

    id: str
    bounds: tuple[float, float, float, float]  # min_x, min_y, max_x, max_y [m]

    def in_bounds(self, x: float, y: float, margin_m: float = 0.0) -> bool: ...


@runtime_checkable
class RobotBackend(Protocol):
    robot: RobotModel  # the robot model: topics, command types, sensor frames
    world: WorldView
    lights: tuple[LightSource, ...]
    state: RobotState  # true pose (a real robot's stays at the origin), contacts, distance

    @property
    def topics(self) -> tuple[TopicSpec, ...]: ...

    @property
    def time_s(self) -> float:
        """Run time [s] the backend has reached."""
        ...

    @property
    def tick_s(self) -> float:
        """[s] the smallest step that moves it on (a physics tick; a real robot's poll)."""
        ...

    @property
    def odometry_origin(self) -> Pose2D: ...

    def reset(self, seed: int | None = None) -> list[Published]: ...

    def step(self, dt_s: float) -> list[Published]: ...

    def apply(self, topic: str, message: object) -> None: ...

    def read(self, topic: str) -> object | None: ...

    def next_publication_s(self) -> float:
        """Run time [s] of the next message it will publish (a real robot: the next poll)."""
        ...

    def drain_events(self) -> list[SimEvent]: ...

    def note_readers(self, is_read: Callable[[str], bool]) -> None:
        """`is_read(topic)`: whether a node of the run reads that topic now (the run's bus).
        A real robot that goes silent names such a topic first; a simulation has no use for it."""
        ...

    def press_button(self, pressed: bool) -> None: ...

    def move_light(self, name: str, x: float, y: float) -> None: ...

    def stop(self) -> None:
        """Zero velocity on every velocity topic, now."""
        ...

    def take_logs(self) -> list[str]:
        """What the robot itself logged since the last call (a simulated one logs nothing)."""
        ...
