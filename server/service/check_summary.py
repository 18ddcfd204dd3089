"""A check from the student page, summed up: an exercise's grading cases (seed and start pose,
server/exercises/grading.py `cases_of`) started as separate runs (POST /api/runs with `case`),
judged the way `robodojo check` judges them: each check by its worst case
(model.Comparison.worst: the largest value for "<=", the smallest for ">="; a case with no
value, a run that never settled, is the worst of all).

    summarize(exercise, records, run_times)   # -> the JSON GET /api/exercises/{id}/check answers

Pure: the route reads the records and the running runs' clocks and hands them in.
"""

from __future__ import annotations

import math

from server.exercises.grading import cases_of
from server.exercises.model import Exercise
from server.runs.state import RunState
from server.store.models import RunRecord


def summarize(
    exercise: Exercise, records: list[RunRecord], run_times: dict[str, float]
) -> dict[str, object]:
    """`records`: the check's runs, case 0 first; `run_times`: [s] the run clock of those still
    running (ended runs have theirs stored)."""
    case_count = len(cases_of(exercise))
    runs = []
    ended = []
    for index, record in enumerate(records):
        state = RunState(record.state)
        time_s = run_times.get(record.id, record.sim_time_s or 0.0)
        runs.append(
            {
                "id": record.id,
                "case": index,
                "seed": record.seed,
                "state": str(state),
                "reason": record.reason,
                "time_s": time_s,
                "duration_s": record.duration_s,
                "score": record.score,
                "checks": record.checks or [],
            }
        )
        # Judged: an ended run whose results are stored (the end is stored with them).
        if state.is_end:
            ended.append(record)
    checks = []
    for check in exercise.checks:
        per_case = [_value_of(record, check.name) for record in ended]
        values = [math.nan if value is None else value for value in per_case]
        worst = check.comparison.worst(values) if values else math.nan
        checks.append(
            {
                "name": check.name,
                "description": check.description,
                "unit": check.unit,
                "comparison": str(check.comparison),
                "threshold": check.threshold,
                "value": worst if math.isfinite(worst) else None,
                "passed": bool(values) and check.comparison.passes(worst, check.threshold),
                "per_case": per_case,
            }
        )
    done = len(ended) == case_count
    every_finished = all(RunState(r.state) is RunState.FINISHED for r in ended)
    return {
        "exercise": exercise.id,
        "cases": case_count,
        "started": len(records),
        "ended": len(ended),
        "done": done,
        "runs": runs,
        "checks": checks,
        # Like `robodojo check`: every check passes on its worst case, every case ran to its end.
        "passed": (every_finished and all(c["passed"] for c in checks)) if done else None,
    }


def _value_of(record: RunRecord, name: str) -> float | None:
    for check in record.checks or []:
        if check.get("name") == name:
            value = check.get("value")
            return float(value) if isinstance(value, int | float) else None
    return None
