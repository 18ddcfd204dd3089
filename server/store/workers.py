"""The cluster's workers as the store keeps them (issue 16): each reports itself every
REPORT_PERIOD_S; one unseen for LOST_AFTER_S is lost, and its runs end "failed: worker lost".

The reaper runs in every web process and every worker; its updates are idempotent (each run's
end is written only while the run is still active), so two reapers never end a run twice and
exactly one of them learns that it ended it (and tells the run's viewers).

    with store.session() as db:
        report(db, WorkerReport("lab1:4242", "lab1", capacity=8, running=2, state="ready"))
        ended = reap(db, now=time.time(), alive=lambda worker_id: False)
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import StrEnum

from sqlalchemy import delete, select, update
from sqlalchemy.orm import Session as Db

from server.runs.state import RunState
from server.store.models import RunRecord, WorkerRecord
from server.store.runs import ACTIVE_STATES

# Timing of the roster, each with why.
REPORT_PERIOD_S = 2.0  # [s] a worker renews its row this often
LOST_AFTER_S = 6.0  # [s] three missed reports: lost (ends its runs within 10 s of a SIGKILL)
FORGET_AFTER_S = 3600.0  # [s] a lost or stopped worker's row is kept this long for the admin
WORKER_LOST = "failed: worker lost (the machine or process running it stopped answering)"


class WorkerState(StrEnum):
    READY = "ready"  # taking runs
    PAUSED = "paused"  # not taking runs: its message says why (the database is away)
    STOPPING = "stopping"  # finishing its runs, taking no more
    STOPPED = "stopped"  # exited cleanly
    LOST = "lost"  # stopped reporting


@dataclass(frozen=True, slots=True)
class WorkerReport:
    id: str  # host:pid
    host: str
    capacity: int
    running: int
    state: str
    message: str = ""
    robots: list[str] = field(default_factory=list)
    started_at: float = 0.0


def report(db: Db, worker: WorkerReport, now: float | None = None) -> None:
    """Insert or renew a worker's row."""
    now = time.time() if now is None else now
    record = db.get(WorkerRecord, worker.id)
    if record is None:
        db.add(
            WorkerRecord(
                id=worker.id,
                host=worker.host,
                capacity=worker.capacity,
                running=worker.running,
                state=worker.state,
                message=worker.message,
                robots=list(worker.robots),
                started_at=worker.started_at or now,
                last_seen=now,
            )
        )
        return
    record.capacity = worker.capacity
    record.running = worker.running
    record.state = worker.state
    record.message = worker.message
    record.robots = list(worker.robots)
    record.last_seen = now


def listing(db: Db, now: float | None = None) -> list[dict]:
    """Every worker seen in the last hour, newest first, as the admin status shows them."""
    now = time.time() if now is None else now
    rows = db.scalars(
        select(WorkerRecord)
        .where(WorkerRecord.last_seen >= now - FORGET_AFTER_S)
        .order_by(WorkerRecord.started_at.desc())
    )
    return [
        {
            "id": row.id,
            "host": row.host,
            "role": "worker",
            "capacity": row.capacity,
            "running": row.running,
            "state": row.state
            if row.state in (WorkerState.STOPPED, WorkerState.LOST)
            or now - row.last_seen <= LOST_AFTER_S
            else str(WorkerState.LOST),
            "message": row.message,
            "robots": list(row.robots or []),
            "last_seen_s": round(now - row.last_seen, 1),
        }
        for row in rows
    ]


def capacity(db: Db, now: float | None = None) -> int:
    """Runs the live, ready workers take at once in all."""
    now = time.time() if now is None else now
    rows = db.scalars(
        select(WorkerRecord.capacity).where(
            WorkerRecord.last_seen >= now - LOST_AFTER_S, WorkerRecord.state == WorkerState.READY
        )
    )
    return sum(rows)


def reap(db: Db, now: float | None = None, alive: Callable[[str], bool] | None = None) -> list[str]:
    """End the active runs of every worker unseen for LOST_AFTER_S ("failed: worker lost") and
    mark it lost. `alive(worker_id)`: a second opinion (the worker's Redis heartbeat) for a
    worker that is up but cannot reach this database. Returns the runs this call ended."""
    now = time.time() if now is None else now
    silent = list(
        db.scalars(
            select(WorkerRecord.id).where(
                WorkerRecord.last_seen < now - LOST_AFTER_S,
                WorkerRecord.state != WorkerState.LOST,
            )
        )
    )
    ended: list[str] = []
    for worker_id in silent:
        if alive is not None and alive(worker_id):
            continue
        runs = db.scalars(
            select(RunRecord.id).where(
                RunRecord.worker_id == worker_id, RunRecord.state.in_(ACTIVE_STATES)
            )
        )
        for run_id in list(runs):
            result = db.execute(
                update(RunRecord)
                .where(RunRecord.id == run_id, RunRecord.state.in_(ACTIVE_STATES))
                .values(state=str(RunState.FAILED), reason=WORKER_LOST, ended_at=now)
            )
            if result.rowcount:
                ended.append(run_id)
        # A stopped worker keeps its state; only a silent one becomes lost.
        db.execute(
            update(WorkerRecord)
            .where(WorkerRecord.id == worker_id, WorkerRecord.state != WorkerState.STOPPED)
            .values(state=str(WorkerState.LOST))
        )
    db.execute(delete(WorkerRecord).where(WorkerRecord.last_seen < now - FORGET_AFTER_S))
    return ended
