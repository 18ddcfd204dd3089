"""What an exercise is: a robot in a world with initial conditions, starter code, a reference
solution (never shown to students), scripted events, and checks that grade a run from its
recording. Registered by id in server/exercises/registry.py and validated like robots and worlds.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING

from sandbox.protocol import Clock

if TYPE_CHECKING:
    from server.exercises.evidence import Evidence
    from server.runs.commands import RunCommand

EXERCISE_DIR = Path(__file__).resolve().parent


class Comparison(StrEnum):
    AT_MOST = "<="
    AT_LEAST = ">="

    def passes(self, value: float, threshold: float) -> bool:
        if not math.isfinite(value):
            return False
        return value <= threshold if self is Comparison.AT_MOST else value >= threshold

    def worst(self, values: list[float]) -> float:
        """Over several seeds, the value that decides: the largest for <=, the smallest for >=
        (a non-finite value - a run that never settled - is the worst of all)."""
        if any(not math.isfinite(v) for v in values):
            return math.inf if self is Comparison.AT_MOST else -math.inf
        return max(values) if self is Comparison.AT_MOST else min(values)


@dataclass(frozen=True, slots=True)
class Check:
    """A named metric computed from one run's evidence, with its pass threshold."""

    name: str
    description: str
    unit: str
    comparison: Comparison
    threshold: float
    metric: Callable[[Evidence], float]


@dataclass(frozen=True, slots=True)
class ScriptEvent:
    """Something the exercise does at run time `time_s` [s]: a command of
    server/runs/commands.py such as Light(x, y, name="lamp"), Goal(x, y, yaw), Button(pressed)."""

    time_s: float
    command: RunCommand


@dataclass(frozen=True, slots=True)
class Exercise:
    id: str
    title: str
    robot: str
    world: str
    source: str  # paper and section
    description: str  # what the student is asked to do (shown to students)
    duration_s: float
    checks: tuple[Check, ...]
    reference: tuple[tuple[str, str], ...]  # (node name, file under server/exercises/)
    starter: tuple[tuple[str, str], ...]  # (node name, file under server/exercises/)
    seeds: tuple[int, ...] = (1,)
    clock: Clock = Clock.LOCKSTEP
    spawn: str | None = None
    initial_pose: tuple[float, float, float] | None = None
    # Several start poses (x, y, yaw): one graded run each, seeds taken in turn from `seeds`.
    starts: tuple[tuple[float, float, float], ...] = ()
    light_position: tuple[float, float] | None = None
    script: tuple[ScriptEvent, ...] = ()
    builtin_nodes: tuple[str, ...] = ()  # trusted helpers (server/runs/builtin.py)
    params: dict[str, object] = field(default_factory=dict)
    # Before a run on a real robot, this code must have finished a simulation run of this
    # exercise (server setting ROBODOJO_HARDWARE_GATE switches it off for the whole lab).
    hardware_gate: bool = True
    # The key figure leaderboards rank equal scores by: the name of one of `checks`, better in
    # the direction of its Comparison (a settling time lower, a distance travelled higher).
    # None: equal scores are ranked by who got there first.
    leaderboard_check: str | None = None

    def key_check(self) -> Check | None:
        """The check named by `leaderboard_check`, or None (none named, or a custom exercise
        that left it out of its checks)."""
        for check in self.checks:
            if check.name == self.leaderboard_check:
                return check
        return None

    def code_path(self, relative: str) -> Path:
        return EXERCISE_DIR / relative
