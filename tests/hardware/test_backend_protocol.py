"""Both robots a run can drive, `Simulation` and `HardwareRobot`, implement the declared
`RobotBackend` protocol (server/sim/backend.py): every member, with the same parameters."""

from __future__ import annotations

import inspect

import pytest

from server.hardware.backend import HardwareRobot
from server.hardware.safety import MotionLimits
from server.sim import RobotBackend, Simulation, WorldView


class _IdleLink:
    """A connected robot that says nothing."""

    connected = True
    lost_reason = ""

    def send(self, topic: str, message: object) -> None:
        pass

    def take_received(self) -> list:
        return []


def _protocol_members(protocol: type) -> set[str]:
    own = set(vars(protocol)) | set(getattr(protocol, "__annotations__", {}))
    return {name for name in own if not name.startswith("_")}


def _backends() -> list[object]:
    hardware = HardwareRobot("crowbot", _IdleLink(), MotionLimits(0.2, 2.0, 1.0, 8.0))
    return [Simulation("crowbot", "wall_approach"), hardware]


def test_the_protocol_declares_what_a_run_uses() -> None:
    assert _protocol_members(RobotBackend) >= {
        "robot", "world", "lights", "state", "topics", "time_s", "tick_s", "odometry_origin",
        "reset", "step", "apply", "read", "next_publication_s", "drain_events", "press_button",
        "move_light", "stop", "take_logs", "note_readers",
    }  # fmt: skip


@pytest.mark.parametrize("backend", _backends(), ids=["Simulation", "HardwareRobot"])
def test_each_backend_is_a_robot_backend(backend: object) -> None:
    assert isinstance(backend, RobotBackend)
    for name in sorted(_protocol_members(RobotBackend)):
        assert hasattr(backend, name), f"{type(backend).__name__} lacks {name}"
        declared = inspect.getattr_static(RobotBackend, name, None)
        if inspect.isfunction(declared):
            wanted = list(inspect.signature(declared).parameters)
            got = ["self", *inspect.signature(getattr(backend, name)).parameters]
            assert got == wanted, f"{type(backend).__name__}.{name}{got} != {wanted}"
        elif isinstance(declared, property):
            # A property there is a property (or a plain attribute) here, not a method.
            assert not inspect.ismethod(getattr(backend, name)), name
    for name in _protocol_members(WorldView):
        assert hasattr(backend.world, name), f"{type(backend).__name__}.world lacks {name}"
    assert backend.world.in_bounds(0.5, 0.5, margin_m=0.1)


def test_a_class_missing_a_member_is_not_a_robot_backend() -> None:
    class Partial:
        """Everything but take_logs: not a backend."""

    sim = Simulation("crowbot", "wall_approach")
    for name in _protocol_members(RobotBackend) - {"take_logs"}:
        setattr(Partial, name, getattr(sim, name))
    assert not isinstance(Partial(), RobotBackend)
