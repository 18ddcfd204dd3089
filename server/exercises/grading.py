"""Grading: run an exercise's nodes on each of its seeds, compute every check from each run's
recording, and judge each check by its worst seed."""

from __future__ import annotations

import math
import tempfile
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from functools import partial
from pathlib import Path

from sandbox.launcher import Launcher
from sandbox.protocol import Clock
from server.exercises.evidence import load_evidence
from server.exercises.model import Exercise
from server.exercises.parallel_runs import run_in_processes
from server.runs.result import RunResult
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec
from server.runs.state import RunState


@dataclass(frozen=True, slots=True)
class CheckResult:
    name: str
    description: str
    value: float
    threshold: float
    comparison: str
    unit: str
    passed: bool
    per_seed: tuple[float, ...]


@dataclass(frozen=True, slots=True)
class Grade:
    exercise: str
    checks: tuple[CheckResult, ...]
    runs: tuple[dict, ...]  # per seed: seed, state, reason, run_dir

    @property
    def passed(self) -> bool:
        return all(check.passed for check in self.checks) and all(
            run["state"] == RunState.FINISHED for run in self.runs
        )

    @property
    def score(self) -> float:
        """Fraction of checks passed, 0..1 (a run that did not finish scores 0)."""
        if not self.checks or any(run["state"] != RunState.FINISHED for run in self.runs):
            return 0.0
        return sum(check.passed for check in self.checks) / len(self.checks)

    def summary(self) -> dict:
        return {
            "exercise": self.exercise,
            "passed": self.passed,
            "score": round(self.score, 3),
            "checks": [
                {
                    "name": c.name,
                    "value": c.value,
                    "threshold": c.threshold,
                    "comparison": c.comparison,
                    "unit": c.unit,
                    "passed": c.passed,
                    "per_seed": list(c.per_seed),
                }
                for c in self.checks
            ],
            "runs": list(self.runs),
        }


def reference_nodes(exercise: Exercise) -> tuple[NodeSpec, ...]:
    return _nodes(exercise, exercise.reference)


def starter_nodes(exercise: Exercise) -> tuple[NodeSpec, ...]:
    return _nodes(exercise, exercise.starter)


def _nodes(exercise: Exercise, files: tuple[tuple[str, str], ...]) -> tuple[NodeSpec, ...]:
    return tuple(NodeSpec.from_file(exercise.code_path(path), name) for name, path in files)


def run_spec(
    exercise: Exercise,
    nodes: tuple[NodeSpec, ...],
    seed: int,
    initial_pose: tuple[float, float, float] | None = None,
    clock: Clock | None = None,
) -> RunSpec:
    """The run of one seed; `clock` overrides the exercise's (a check on the other clock)."""
    return RunSpec(
        robot=exercise.robot,
        world=exercise.world,
        nodes=nodes,
        clock=clock or exercise.clock,
        duration_s=exercise.duration_s,
        seed=seed,
        spawn=exercise.spawn,
        initial_pose=initial_pose or exercise.initial_pose,
        light_position=exercise.light_position,
        params=dict(exercise.params),
        script=tuple((e.time_s, e.command) for e in exercise.script),
        builtin_nodes=exercise.builtin_nodes,
    )


def check_values(exercise: Exercise, result: RunResult, run_dir: Path) -> dict[str, float]:
    """Each check's value for one finished run (NaN where the run gave nothing to judge)."""
    evidence = load_evidence(result, run_dir)
    values = {}
    for check in exercise.checks:
        try:
            values[check.name] = float(check.metric(evidence))
        except (ValueError, KeyError, IndexError, ZeroDivisionError):
            values[check.name] = float("nan")  # nothing to judge (the run ended early)
    return values


def judge_run(exercise: Exercise, result: RunResult, run_dir: Path) -> tuple[list[dict], float]:
    """One run judged on its own (a student's run from the web): each check's value against
    its threshold, and the score, the fraction passed (0 when the run did not finish)."""
    values = check_values(exercise, result, run_dir)
    checks = []
    for check in exercise.checks:
        value = values[check.name]
        checks.append(
            {
                "name": check.name,
                "description": check.description,
                "value": value if math.isfinite(value) else None,
                "threshold": check.threshold,
                "comparison": str(check.comparison),
                "unit": check.unit,
                "passed": check.comparison.passes(value, check.threshold),
            }
        )
    finished = result.state is RunState.FINISHED
    score = sum(c["passed"] for c in checks) / len(checks) if checks and finished else 0.0
    return checks, score


@dataclass(frozen=True, slots=True)
class Case:
    """One graded run: its index among the check's runs, its seed and its start pose (None: the
    exercise's own)."""

    index: int
    seed: int
    start: tuple[float, float, float] | None


def cases_of(exercise: Exercise) -> list[Case]:
    """One run per seed, or per start pose (seeds taken in turn)."""
    seeds = exercise.seeds
    if exercise.starts:
        count = max(len(exercise.starts), len(seeds))
        return [
            Case(i, seeds[i % len(seeds)], exercise.starts[i % len(exercise.starts)])
            for i in range(count)
        ]
    return [Case(i, seed, None) for i, seed in enumerate(seeds)]


def run_case(
    exercise: Exercise,
    nodes: tuple[NodeSpec, ...],
    root: Path,
    clock: Clock | None,
    case: Case,
    launcher: Launcher,
) -> tuple[dict, dict[str, float]]:
    """One case run and judged: its summary and each check's value (picklable: a worker
    process sends them back)."""
    run_dir = root / f"run{case.index}-seed{case.seed}"
    spec = run_spec(exercise, nodes, case.seed, case.start, clock)
    result = Run(spec, launcher, run_dir).execute()
    values = check_values(exercise, result, run_dir)
    summary = {
        "seed": case.seed,
        "start": list(case.start) if case.start else None,
        "state": str(result.state),
        "reason": result.reason,
        "run_dir": str(run_dir),
    }
    return summary, values


def grade(
    exercise: Exercise,
    nodes: tuple[NodeSpec, ...],
    launcher: Launcher | None,
    out_dir: Path | None = None,
    clock: Clock | None = None,
    unsafe_no_sandbox: bool = False,
) -> Grade:
    """Run every case of the exercise and judge each check by its worst case.

    `launcher`: None runs each case in a worker process of its own, with its own launcher
    (server/exercises/parallel_runs.py: what `robodojo check` does; `unsafe_no_sandbox` is for
    those launchers). A launcher runs the cases in threads of this process with it (tests that
    share one warm pool): the same values, more slowly, as the runs' loops share one GIL."""
    root = Path(out_dir) if out_dir else Path(tempfile.mkdtemp(prefix=f"check-{exercise.id}-"))
    cases = cases_of(exercise)
    job = partial(run_case, exercise, nodes, root, clock)
    if launcher is None:
        outcomes = run_in_processes(job, cases, unsafe_no_sandbox)
    else:
        # Independent runs go side by side (their nodes are separate processes).
        with ThreadPoolExecutor(max_workers=len(cases)) as pool:
            outcomes = list(pool.map(lambda case: job(case, launcher), cases))
    runs = [summary for summary, _ in outcomes]
    per_check = {c.name: [values[c.name] for _, values in outcomes] for c in exercise.checks}
    results = tuple(
        CheckResult(
            name=check.name,
            description=check.description,
            value=check.comparison.worst(per_check[check.name]),
            threshold=check.threshold,
            comparison=str(check.comparison),
            unit=check.unit,
            passed=check.comparison.passes(
                check.comparison.worst(per_check[check.name]), check.threshold
            ),
            per_seed=tuple(per_check[check.name]),
        )
        for check in exercise.checks
    )
    return Grade(exercise.id, results, tuple(runs))
