"""What a student's sandboxes are doing, as the store knows it: their active runs (each node a
sandbox) and their leases, the sandbox jobs that are not runs (a launch file being read). The
sandbox budget (server/service/sandbox_budget.py) adds these up under the admission lock, so
every web process of a lab agrees on them, as on the run limits.

    with store.exclusive_session() as db:
        held = holding(db, user_id, now)            # -> Holding(runs, run_sandboxes, leases, ...)
        lease_id = take(db, user_id, "launch file", sandboxes=1, now=now, lasts_s=70.0)
    ...
    with store.session() as db:
        give_back(db, lease_id)
"""

from __future__ import annotations

import uuid
from dataclasses import dataclass

from sqlalchemy import delete, select
from sqlalchemy.orm import Session as Db

from server.store.models import RunRecord, SandboxLease
from server.store.runs import ACTIVE_STATES


@dataclass(frozen=True, slots=True)
class Holding:
    """A student's sandbox jobs now."""

    runs: int  # active runs (queued ones too: their nodes are about to start)
    run_sandboxes: int  # their nodes, one sandbox each
    leases: int  # other jobs (launch files being read)
    lease_sandboxes: int

    @property
    def jobs(self) -> int:
        return self.runs + self.leases

    @property
    def sandboxes(self) -> int:
        return self.run_sandboxes + self.lease_sandboxes


def holding(db: Db, user_id: str, now: float) -> Holding:
    """The student's active runs and unexpired leases."""
    codes = db.scalars(
        select(RunRecord.code).where(
            RunRecord.user_id == user_id, RunRecord.state.in_(ACTIVE_STATES)
        )
    ).all()
    leases = db.scalars(
        select(SandboxLease.sandboxes).where(
            SandboxLease.user_id == user_id, SandboxLease.expires_at > now
        )
    ).all()
    return Holding(
        runs=len(codes),
        run_sandboxes=sum(len(code or ()) for code in codes),
        leases=len(leases),
        lease_sandboxes=sum(leases),
    )


def take(db: Db, user_id: str, kind: str, sandboxes: int, now: float, lasts_s: float) -> str:
    """Record a job's lease (and forget leases that expired); returns its id."""
    db.execute(delete(SandboxLease).where(SandboxLease.expires_at <= now))
    lease_id = uuid.uuid4().hex
    db.add(
        SandboxLease(
            id=lease_id,
            user_id=user_id,
            kind=kind[:32],
            sandboxes=sandboxes,
            created_at=now,
            expires_at=now + lasts_s,
        )
    )
    db.flush()
    return lease_id


def give_back(db: Db, lease_id: str) -> None:
    db.execute(delete(SandboxLease).where(SandboxLease.id == lease_id))
