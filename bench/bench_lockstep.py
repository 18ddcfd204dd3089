"""A 60 s lockstep CrowBot run with a 10 Hz node: in the server process, and `robodojo run`.

Prints median and p99 over --repeats of
- `Run.execute()` wall time, node start from the warm pool included (issue 18 target: < 0.5 s),
  with the server process's CPU time and where the wall time went (physics and sensors,
  node round trips, the rest of the clock loop, start and finish);
- `robodojo run` of the same from the shell, interpreter start and cold node included
  (target: < 1 s), with the CPU time of the command and its children;
- the simulation alone, stepped as that run steps it (50 ms sensor period, 10 Hz commands), with
  the ticks evaluated in runs and one by one (`tick_runs=False`, the 1 kHz reference).

Usage: PYTHONPATH=. python bench/bench_lockstep.py [--repeats 10] [--skip-cli]
The machine is shared: read CPU time beside wall time.
"""

from __future__ import annotations

import argparse
import inspect
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from sandbox.launcher import Launcher
from sandbox.msgs.geometry_msgs import Twist, Vector3
from sandbox.protocol import Clock
from server.runs import core
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState
from server.sim import Simulation

CONTROLLER = """
RATE_HZ = 10
SUBSCRIBE = ["Distance"]

def step(obs):
    if obs.Distance is None or obs.Distance.data == 0:
        return (0.0, 0.0)
    return (0.4 * (obs.Distance.data / 100 - 0.2), 0.0)
"""
DURATION_S = 60.0  # [s] simulated
REPO = Path(__file__).resolve().parent.parent


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def line(label: str, values: list[float], cpu: list[float] | None = None) -> str:
    median, p99 = statistics.median(values), percentile(values, 0.99)
    text = f"{label:<46} wall p50 {median:6.3f} s  p99 {p99:6.3f} s"
    if cpu:
        text += f"   cpu p50 {statistics.median(cpu):6.3f} s"
    return text + f"  (n={len(values)})"


class Timed:
    """Adds up the wall time spent in some methods of the run engine, per run."""

    def __init__(self) -> None:
        self.totals: dict[str, float] = {}
        for owner, name, label in (
            (core.RunCore, "advance_to", "advance"),
            (core.RunCore, "wake", "node round trips"),
            (Simulation, "step", "physics+sensors"),
            (core.RunCore, "prepare", "prepare"),
            (core.RunCore, "start_nodes", "start nodes"),
            (core.RunCore, "finish", "finish"),
        ):
            self._wrap(owner, name, label)

    def _wrap(self, owner: type, name: str, label: str) -> None:
        original = getattr(owner, name)
        totals = self.totals

        def timed(*args, **kwargs):
            started = time.perf_counter()
            try:
                return original(*args, **kwargs)
            finally:
                totals[label] = totals.get(label, 0.0) + time.perf_counter() - started

        setattr(owner, name, timed)

    def take(self) -> dict[str, float]:
        taken = dict(self.totals)
        self.totals.clear()
        return taken


def bench_in_process(repeats: int, out: Path) -> None:
    spec = RunSpec(
        "crowbot",
        "wall_approach",
        (NodeSpec("controller", CONTROLLER, "controller.py"),),
        clock=Clock.LOCKSTEP,
        duration_s=DURATION_S,
    )
    launcher = Launcher(pool_size=1)
    timed = Timed()
    walls, cpus, parts = [], [], []
    try:
        for attempt in range(repeats + 1):  # the first warms caches up and is not counted
            while len(launcher._pool) < 1:
                time.sleep(0.02)
            timed.take()
            started, cpu = time.perf_counter(), time.process_time()
            result = Run(spec, launcher, out / f"run{attempt}").execute()
            if attempt:
                walls.append(time.perf_counter() - started)
                cpus.append(time.process_time() - cpu)
                parts.append(timed.take())
            assert result.state is RunState.FINISHED, result.reason
    finally:
        launcher.close()
    print(line("Run.execute(), 60 s, 10 Hz node, warm pool", walls, cpus))
    advance = [p["advance"] - p["physics+sensors"] for p in parts]
    named = {
        "physics+sensors": [p["physics+sensors"] for p in parts],
        "node round trips (600)": [p["node round trips"] for p in parts],
        "rest of advance (routing, recording, /tf)": advance,
        "start (prepare + nodes) and finish": [
            p["prepare"] + p["start nodes"] + p["finish"] for p in parts
        ],
    }
    for label, values in named.items():
        print(f"    {label:<42} p50 {statistics.median(values):6.3f} s")


def bench_cli(repeats: int, out: Path, node_file: Path) -> None:
    command = [
        sys.executable,
        "-m",
        "server.cli",
        "run",
        "--robot",
        "crowbot",
        "--world",
        "wall_approach",
        "--node",
        str(node_file),
        "--duration",
        str(DURATION_S),
    ]
    # As an installed lab runs it: bytecode cached (a session with PYTHONDONTWRITEBYTECODE
    # would compile every module on each start, ~0.1 s), so one uncounted run first.
    env = {key: value for key, value in os.environ.items() if key != "PYTHONDONTWRITEBYTECODE"}
    env["PYTHONPATH"] = str(REPO)
    walls, cpus = [], []
    for attempt in range(-1, repeats):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        started = time.perf_counter()
        done = subprocess.run(
            [*command, "--out", str(out / f"cli{attempt + 1}")],
            cwd=REPO,
            capture_output=True,
            text=True,
            env=env,
        )
        wall = time.perf_counter() - started
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        assert done.returncode == 0, done.stderr
        if attempt >= 0:
            walls.append(wall)
            cpus.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    print(line(f"robodojo run {node_file.name}, 60 s (from the shell)", walls, cpus))


def bench_simulation(repeats: int) -> None:
    if "tick_runs" not in inspect.signature(Simulation).parameters:  # code before issue 18
        modes = [{}]
    else:
        modes = [{"tick_runs": True}, {"tick_runs": False}]
    for mode in modes:
        cpus = []
        for _ in range(repeats):
            sim = Simulation("crowbot", "wall_approach", seed=0, **mode)
            started = time.process_time()
            for _ in range(round(DURATION_S * 10)):
                reading = sim.read("Distance")
                speed = (
                    0.0
                    if reading is None or reading.data == 0
                    else 0.4 * (reading.data / 100 - 0.2)
                )
                sim.apply("Control", Twist(linear=Vector3(x=speed)))
                sim.step(0.05)
                sim.step(0.05)
            cpus.append(time.process_time() - started)
        label = (
            "one tick at a time (1 kHz reference)"
            if not mode.get("tick_runs", False)
            else "in runs of ticks"
        )
        print(
            f"simulation alone, 60 s, {label:<38} cpu p50 {statistics.median(cpus):6.3f} s"
            f"  p99 {percentile(cpus, 0.99):6.3f} s"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=10)
    parser.add_argument("--skip-cli", action="store_true")
    args = parser.parse_args()
    print(f"load average at start: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    with tempfile.TemporaryDirectory(prefix="robodojo-bench-") as tmp:
        out = Path(tmp)
        bench_simulation(args.repeats)
        bench_in_process(args.repeats, out)
        if not args.skip_cli:
            node_file = out / "controller_10hz.py"
            node_file.write_text(CONTROLLER)
            bench_cli(args.repeats, out, node_file)
            bench_cli(args.repeats, out, REPO / "examples" / "step_api" / "crowbot.py")
    print(f"load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
