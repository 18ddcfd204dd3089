"""Shared by the 3D view tests: a viser server per test (cheap: ~40 ms), decoding of what viser
sends on its websocket, and real recordings made by real runs (a sandboxed launcher, as
tests/runs/conftest.py makes one)."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from pathlib import Path

import msgspec
import pytest
import zstandard

from sandbox import bwrap
from sandbox.launcher import Launcher
from sandbox.limits import DEFAULT_LIMITS
from sandbox.protocol import Clock
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState

# A CrowBot that turns, lights its LEDs red after 0.5 s and sounds its buzzer at 1 s.
CROWBOT_SHOW = """\
RATE_HZ = 10


def step(obs):
    command = {"Control": (0.05, 0.5)}
    if obs.time >= 0.5:
        command["Leds"] = [255, 0, 0]
    if 1.0 <= obs.time < 1.1:
        command["Buzzer"] = True
    return command
"""
# A TurtleBot that rolls ahead while the planner answers the waypoints with a path.
TURTLEBOT_ROLL = """\
RATE_HZ = 10


def step(obs):
    return (0.1, 0.0)
"""
OFFICE_WAYPOINTS = [(2.0, 1.3, 0.0), (6.0, 1.4, 0.0)]  # the first is the start: reached at once


def viser_messages(frame: bytes) -> list[dict]:
    """The messages in one viser websocket frame (viser/infra/_infra.py `_message_producer`:
    8 bytes decompressed size, 8 bytes compressed size, zstd msgpack, then raw buffers)."""
    size = int.from_bytes(frame[:8], "little")
    compressed = int.from_bytes(frame[8:16], "little")
    inner = zstandard.ZstdDecompressor().decompress(frame[16 : 16 + compressed], size)
    return msgspec.msgpack.decode(inner)["messages"]


@pytest.fixture
def viser_server():
    import viser

    from server.viz.manager import _quiet_viser

    _quiet_viser()
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    yield server
    server.stop()


@pytest.fixture(scope="session")
def launcher() -> Iterator[Launcher]:
    problem = bwrap.probe()
    if problem:
        pytest.fail(f"the 3D view tests need bubblewrap: {problem} (./scripts/test installs it)")
    limits = dataclasses.replace(DEFAULT_LIMITS, step_budget_s=2.0, first_step_budget_s=8.0)
    launcher = Launcher(limits=limits, pool_size=1)
    yield launcher
    launcher.close()


def crowbot_spec(duration_s: float = 2.0, clock: Clock = Clock.LOCKSTEP) -> RunSpec:
    return RunSpec(
        "crowbot",
        "light_arena",
        (NodeSpec("show", CROWBOT_SHOW, "show.py"),),
        clock=clock,
        duration_s=duration_s,
    )


def turtlebot_spec(duration_s: float = 3.0) -> RunSpec:
    return RunSpec(
        "turtlebot",
        "office",
        (NodeSpec("roll", TURTLEBOT_ROLL, "roll.py"),),
        duration_s=duration_s,
        spawn="start",
        builtin_nodes=("map_server", "localization", "waypoints", "planner"),
        params={"waypoints": OFFICE_WAYPOINTS},
    )


def record(spec: RunSpec, launcher: Launcher, out_dir: Path) -> Path:
    run = Run(spec, launcher, out_dir)
    result = run.execute()
    assert result.state is RunState.FINISHED, result.reason
    return out_dir


@pytest.fixture(scope="session")
def crowbot_run(launcher, tmp_path_factory) -> Path:
    """The run folder of a finished 2 s CrowBot run in the light arena."""
    return record(crowbot_spec(), launcher, tmp_path_factory.mktemp("crowbot"))


@pytest.fixture(scope="session")
def turtlebot_run(launcher, tmp_path_factory) -> Path:
    """The run folder of a finished 3 s TurtleBot run in the office, with a plan."""
    return record(turtlebot_spec(), launcher, tmp_path_factory.mktemp("turtlebot"))
