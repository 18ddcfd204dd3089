"""Run a few ROS 2 nodes, written inline in a test, as one real run (server.runs.run.Run with
the sandbox launcher), and read back their logs and recording (tests/corpus/harness.Outcome)."""

from __future__ import annotations

import textwrap
from pathlib import Path

from sandbox.protocol import Clock
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from tests.corpus.harness import Outcome


def run_nodes(
    launcher,
    out_dir: Path,
    nodes: dict[str, str],
    *,
    robot: str = "crowbot",
    world: str = "wall_approach",
    duration_s: float = 4.0,
    clock: Clock = Clock.LOCKSTEP,
    spawn: str | None = None,
    builtin_nodes: tuple[str, ...] = (),
) -> Outcome:
    """Run each `name: code` of `nodes` as a node of one run for `duration_s` of run time."""
    specs = tuple(
        NodeSpec(name=name, code=textwrap.dedent(code), filename=f"{name}.py")
        for name, code in nodes.items()
    )
    spec = RunSpec(
        robot=robot,
        world=world,
        nodes=specs,
        clock=clock,
        duration_s=duration_s,
        seed=1,
        spawn=spawn,
        **({"builtin_nodes": builtin_nodes} if builtin_nodes else {}),
    )
    result = Run(spec, launcher, out_dir).execute()
    return Outcome(str(result.state), result.reason, out_dir, clock)
