"""Runs as the store keeps them: created when asked for, updated on every state change, filled
with metrics and check results when they end, so a restart loses none of it. Runs that were
active when the server stopped are marked interrupted at the next start."""

from __future__ import annotations

import time
from dataclasses import dataclass

from sqlalchemy import func, select, update
from sqlalchemy.orm import Session as Db

from server.runs.state import RunState
from server.store.models import RunRecord

ACTIVE_STATES = tuple(
    str(s) for s in (RunState.CREATED, RunState.STARTING, RunState.RUNNING, RunState.PAUSED,
                     RunState.STOPPING)
)  # fmt: skip
INTERRUPTED_BY_RESTART = "interrupted: the server stopped while the run was active"
MAX_LISTED = 500  # runs per page of a listing


def add(db: Db, record: RunRecord) -> RunRecord:
    db.add(record)
    db.flush()
    return record


def get(db: Db, run_id: str) -> RunRecord | None:
    return db.get(RunRecord, run_id)


def set_state(db: Db, run_id: str, state: str, reason: str = "") -> None:
    values: dict = {"state": state}
    if reason:
        values["reason"] = reason
    if state == str(RunState.RUNNING):
        values["started_at"] = time.time()
    db.execute(update(RunRecord).where(RunRecord.id == run_id).values(**values))


@dataclass(frozen=True, slots=True)
class RunFilter:
    user_id: str | None = None
    exercise_id: str | None = None
    robot: str | None = None
    state: str | None = None  # a RunState, or "active" for every state before the end
    since: float | None = None  # [epoch s] created at or after
    until: float | None = None  # [epoch s] created before
    limit: int = 100
    offset: int = 0


def listing(db: Db, where: RunFilter) -> tuple[list[RunRecord], int]:
    """A page of runs, newest first, and how many match in all."""
    conditions = []
    if where.user_id is not None:
        conditions.append(RunRecord.user_id == where.user_id)
    if where.exercise_id is not None:
        conditions.append(RunRecord.exercise_id == where.exercise_id)
    if where.robot is not None:
        conditions.append(RunRecord.robot == where.robot)
    if where.state == "active":  # every state before the end
        conditions.append(RunRecord.state.in_(ACTIVE_STATES))
    elif where.state is not None:
        conditions.append(RunRecord.state == where.state)
    if where.since is not None:
        conditions.append(RunRecord.created_at >= where.since)
    if where.until is not None:
        conditions.append(RunRecord.created_at < where.until)
    total = db.scalar(select(func.count()).select_from(RunRecord).where(*conditions)) or 0
    rows = db.scalars(
        select(RunRecord)
        .where(*conditions)
        .order_by(RunRecord.created_at.desc(), RunRecord.id)
        .limit(min(where.limit, MAX_LISTED))
        .offset(where.offset)
    )
    return list(rows), total


GATE_RUNS_SEARCHED = 200  # the newest finished runs compared; older passes must be redone


def finished_simulation_run(
    db: Db, user_id: str, exercise_id: str | None, robot: str, code: list[dict]
) -> str | None:
    """The id of the newest simulation run of this user, exercise (None: free play) and robot
    that finished with exactly this code, or None: the simulation gate before a hardware run."""
    query = (
        select(RunRecord)
        .where(
            RunRecord.user_id == user_id,
            RunRecord.state == str(RunState.FINISHED),
            RunRecord.robot == robot,
            RunRecord.exercise_id.is_(None)
            if exercise_id is None
            else RunRecord.exercise_id == exercise_id,
        )
        .order_by(RunRecord.created_at.desc())
        .limit(GATE_RUNS_SEARCHED)
    )
    for record in db.scalars(query):
        if record.code == code and record.hardware is None:
            return record.id
    return None


def active_count(db: Db, user_id: str | None = None) -> int:
    query = select(func.count()).select_from(RunRecord).where(RunRecord.state.in_(ACTIVE_STATES))
    if user_id is not None:
        query = query.where(RunRecord.user_id == user_id)
    return db.scalar(query) or 0


def claim(db: Db, run_id: str, worker_id: str) -> bool:
    """A worker takes a queued run: True only for the one whose update found it still "created"
    (a job delivered twice, or to a worker after the run was stopped, is not run again)."""
    result = db.execute(
        update(RunRecord)
        .where(RunRecord.id == run_id, RunRecord.state == str(RunState.CREATED))
        .values(state=str(RunState.STARTING), worker_id=worker_id)
    )
    return (result.rowcount or 0) == 1


def end_queued(db: Db, run_id: str, state: str, reason: str) -> bool:
    """End a run no worker has claimed yet (stopped while queued); False when it was claimed."""
    result = db.execute(
        update(RunRecord)
        .where(RunRecord.id == run_id, RunRecord.state == str(RunState.CREATED))
        .values(state=state, reason=reason, ended_at=time.time())
    )
    return (result.rowcount or 0) == 1


def end_if_active(db: Db, run_id: str, state: str, reason: str) -> bool:
    """End a run that has not ended yet (a later end never overwrites the first one)."""
    result = db.execute(
        update(RunRecord)
        .where(RunRecord.id == run_id, RunRecord.state.in_(ACTIVE_STATES))
        .values(state=state, reason=reason, ended_at=time.time())
    )
    return (result.rowcount or 0) == 1


def queued_before(db: Db, cutoff: float, limit: int = MAX_LISTED) -> list[str]:
    """Runs still waiting for a worker ("created") that were made before `cutoff` [epoch s]."""
    query = (
        select(RunRecord.id)
        .where(RunRecord.state == str(RunState.CREATED), RunRecord.created_at < cutoff)
        .limit(limit)
    )
    return list(db.scalars(query))


def mark_interrupted(db: Db) -> int:
    """At start-up: every run still marked active was cut off by the last stop."""
    result = db.execute(
        update(RunRecord)
        .where(RunRecord.state.in_(ACTIVE_STATES))
        .values(
            state=str(RunState.INTERRUPTED), reason=INTERRUPTED_BY_RESTART, ended_at=time.time()
        )
    )
    return result.rowcount or 0
