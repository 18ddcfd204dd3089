"""Disk budgets and retention for run files (issue 14, finding 4).

Every run leaves a directory (recording, node logs, artifacts, metrics.json, graph.json). Its
size is measured once, when the run ends, and kept in the run's row (`runs.disk_bytes`), so the
budget check at each start adds numbers in the database instead of walking every directory.
Retention removes the directory of runs that ended more than `retention_days` ago; the row stays
(metrics, checks, score), with `files_removed_at` set so the file routes can say why.
"""

from __future__ import annotations

import logging
import os
import shutil
import time
from dataclasses import dataclass
from pathlib import Path

from sqlalchemy import func, select
from sqlalchemy.orm import Session as Db

from server.store import workspaces
from server.store.models import LabSetting, RunRecord, User

log = logging.getLogger("robodojo.disk")

DAY_S = 86400.0  # [s]
TOP_STUDENTS = 10  # students listed by disk use on the instructor's status
RETENTION_KEY = "retention_days"
FILES_REMOVED = (
    "this run's files (recording, logs, artifacts) were removed by the lab's retention policy "
    "({days:g} days); its metrics, checks and score are kept"
)


class DiskBudgetError(Exception):
    """A new run would go over a disk budget; the message says how much is used and what to do."""


def dir_bytes(path: Path) -> int:
    """[B] the sum of the sizes of the files below `path` (0 if it is not there)."""
    total = 0
    for root, _dirs, files in os.walk(path):
        for name in files:
            try:
                total += os.lstat(os.path.join(root, name)).st_size
            except OSError:
                continue
    return total


def _mib(size: int) -> str:
    return f"{size / 2**20:.1f} MiB"


def _on_disk():
    return RunRecord.files_removed_at.is_(None)


def used_by(db: Db, user_id: str | None = None) -> int:
    """[B] the measured size of the runs still on disk: one student's, or everyone's."""
    query = select(func.coalesce(func.sum(RunRecord.disk_bytes), 0)).where(_on_disk())
    if user_id is not None:
        query = query.where(RunRecord.user_id == user_id)
    return int(db.scalar(query) or 0)


def check_budgets(db: Db, user_id: str, settings) -> None:
    """Raises DiskBudgetError when the student's or the lab's runs, with their saved code's
    version history (store/workspaces.py caps it per workspace), fill their budget."""
    mine_budget = settings.student_disk_budget_bytes
    if mine_budget:
        runs, history = used_by(db, user_id), workspaces.history_bytes(db, user_id)
        if runs + history >= mine_budget:
            raise DiskBudgetError(
                f"your runs use {_mib(runs)} of disk and your saved code's history "
                f"{_mib(history)}; your budget is {_mib(mine_budget)}. "
                "No new run can start until space is freed: ask your instructor for a larger "
                "budget, or for old runs' files to be removed (retention)"
            )
    lab_budget = settings.lab_disk_budget_bytes
    if lab_budget:
        lab = used_by(db) + workspaces.history_bytes(db)
        if lab >= lab_budget:
            raise DiskBudgetError(
                f"the lab's runs and saved code use {_mib(lab)} of disk; the lab's budget is "
                f"{_mib(lab_budget)}. No new runs can start until space is freed: ask your "
                "instructor"
            )


def retention_days(db: Db, settings) -> float:
    """[days] the instructor's retention if set, else the ROBODOJO_RETENTION_DAYS default."""
    row = db.get(LabSetting, RETENTION_KEY)
    if row is None:
        return float(settings.retention_days)
    return float(row.value["value"])


def set_retention_days(db: Db, days: float) -> None:
    row = db.get(LabSetting, RETENTION_KEY)
    if row is None:
        db.add(LabSetting(key=RETENTION_KEY, value={"value": days}, updated_at=time.time()))
    else:
        row.value = {"value": days}
        row.updated_at = time.time()


def files_removed_sentence(record: RunRecord, days: float) -> str | None:
    if record.files_removed_at is None:
        return None
    return FILES_REMOVED.format(days=days)


@dataclass(frozen=True, slots=True)
class SweepResult:
    measured: int  # ended runs measured for the first time (e.g. cut off by a restart)
    removed: int  # runs whose files retention removed
    freed_bytes: int  # [B]


def sweep(store, settings, now: float | None = None) -> SweepResult:
    """Measure ended runs not measured yet, then remove the files of runs ended too long ago."""
    from server.store.runs import ACTIVE_STATES

    now = time.time() if now is None else now
    with store.session() as db:
        days = retention_days(db, settings)
        unmeasured = list(
            db.scalars(
                select(RunRecord).where(
                    RunRecord.disk_bytes.is_(None),
                    _on_disk(),
                    RunRecord.state.not_in(ACTIVE_STATES),
                )
            )
        )
        for record in unmeasured:
            record.disk_bytes = dir_bytes(Path(record.run_dir))
    removed = freed = 0
    if days > 0:
        cutoff = now - days * DAY_S
        with store.session() as db:
            old = list(
                db.scalars(
                    select(RunRecord).where(
                        _on_disk(),
                        RunRecord.state.not_in(ACTIVE_STATES),
                        RunRecord.ended_at.is_not(None),
                        RunRecord.ended_at < cutoff,
                    )
                )
            )
            for record in old:
                shutil.rmtree(record.run_dir, ignore_errors=True)
                freed += record.disk_bytes or 0
                record.disk_bytes = 0
                record.files_removed_at = now
                removed += 1
    if removed:
        log.info("retention (%g days): removed the files of %d run(s), %d bytes", days, removed,
                 freed)  # fmt: skip
    return SweepResult(len(unmeasured), removed, freed)


def disk_status(db: Db, settings) -> dict:
    """What the instructor's status shows: bytes used by runs, the budgets, the top students."""
    rows = db.execute(
        select(RunRecord.user_id, User.name, func.sum(RunRecord.disk_bytes).label("bytes"))
        .join(User, User.id == RunRecord.user_id)
        .where(_on_disk(), RunRecord.disk_bytes.is_not(None))
        .group_by(RunRecord.user_id, User.name)
        .order_by(func.sum(RunRecord.disk_bytes).desc())
        .limit(TOP_STUDENTS)
    ).all()
    removed = db.scalar(
        select(func.count()).select_from(RunRecord).where(RunRecord.files_removed_at.is_not(None))
    )
    return {
        "runs_bytes": used_by(db),
        "history_bytes": workspaces.history_bytes(db),
        "lab_budget_bytes": settings.lab_disk_budget_bytes,
        "student_budget_bytes": settings.student_disk_budget_bytes,
        "retention_days": retention_days(db, settings),
        "runs_with_files_removed": int(removed or 0),
        "top_students": [
            {"user_id": user_id, "name": name, "bytes": int(size or 0)}
            for user_id, name, size in rows
        ],
    }
