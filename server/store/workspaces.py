"""Students' code: a workspace per exercise (or per robot, for free play), a file per node,
every save a new version. Restoring an old version saves it again as the newest.

History is capped (issue 33: 60 saves of a 1 MB data file grew the database by 56 MB): a save
keeps a file's newest `HistoryCaps.versions_per_file` versions and, across the workspace, the
newest versions whose sizes add up to `HistoryCaps.workspace_bytes`, pruning the oldest first.
The newest version of every file is never pruned (the workspace's own caps bound those). What a
student's history holds counts in their disk budget (`history_bytes`, server/service/disk.py).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from sqlalchemy import delete, func, select
from sqlalchemy.orm import Session as Db

from server.store.models import CodeVersion

MAX_VERSIONS_LISTED = 200  # the newest this many versions of a file are listed


@dataclass(frozen=True, slots=True)
class HistoryCaps:
    """What one workspace's history keeps (the values come from the settings' table)."""

    versions_per_file: int  # a file's newest this many versions
    workspace_bytes: int  # [B] every version of every file of the workspace together


def latest_files(db: Db, user_id: str, workspace: str) -> list[CodeVersion]:
    """The newest version of every file in a workspace, by file name."""
    newest = (
        select(CodeVersion.filename, func.max(CodeVersion.version).label("version"))
        .where(CodeVersion.user_id == user_id, CodeVersion.workspace == workspace)
        .group_by(CodeVersion.filename)
        .subquery()
    )
    query = (
        select(CodeVersion)
        .join(
            newest,
            (CodeVersion.filename == newest.c.filename) & (CodeVersion.version == newest.c.version),
        )
        .where(CodeVersion.user_id == user_id, CodeVersion.workspace == workspace)
        .order_by(CodeVersion.filename)
    )
    return list(db.scalars(query))


def save(
    db: Db,
    user_id: str,
    workspace: str,
    filename: str,
    code: str,
    caps: HistoryCaps | None = None,
) -> CodeVersion:
    """A new version, unless the code is the same as the newest (autosave saves often); then the
    history pruned to `caps` (None: kept whole)."""
    current = db.scalar(
        select(CodeVersion)
        .where(
            CodeVersion.user_id == user_id,
            CodeVersion.workspace == workspace,
            CodeVersion.filename == filename,
        )
        .order_by(CodeVersion.version.desc())
        .limit(1)
    )
    if current is not None and current.code == code:
        return current
    version = CodeVersion(
        user_id=user_id,
        workspace=workspace,
        filename=filename,
        version=(current.version + 1) if current else 1,
        code=code,
        created_at=time.time(),
        size_bytes=len(code.encode()),
    )
    db.add(version)
    db.flush()
    if caps is not None:
        prune(db, user_id, workspace, filename, caps)
    return version


def prune(db: Db, user_id: str, workspace: str, filename: str, caps: HistoryCaps) -> int:
    """Remove the versions past `caps`, oldest first, never a file's newest; returns how many."""
    mine = (CodeVersion.user_id == user_id) & (CodeVersion.workspace == workspace)
    newest_ids = select(func.max(CodeVersion.id)).where(mine).group_by(CodeVersion.filename)
    removed = 0
    # A file's versions past its newest `versions_per_file` (versions are numbered 1, 2, ...).
    newest = db.scalar(
        select(func.max(CodeVersion.version)).where(mine, CodeVersion.filename == filename)
    )
    if newest is not None and newest > caps.versions_per_file:
        done = db.execute(
            delete(CodeVersion).where(
                mine,
                CodeVersion.filename == filename,
                CodeVersion.version <= newest - caps.versions_per_file,
            )
        )
        removed += done.rowcount or 0
    # Then the workspace's bytes: the oldest versions (of any file) until the rest fit.
    total = int(db.scalar(select(func.coalesce(func.sum(CodeVersion.size_bytes), 0)).where(mine)))
    if total > caps.workspace_bytes:
        doomed: list[int] = []
        oldest_first = db.execute(
            select(CodeVersion.id, CodeVersion.size_bytes)
            .where(mine, CodeVersion.id.not_in(newest_ids))
            .order_by(CodeVersion.created_at, CodeVersion.id)
        )
        for version_id, size in oldest_first:
            if total <= caps.workspace_bytes:
                break
            doomed.append(version_id)
            total -= size
        for start in range(0, len(doomed), 500):  # bounded IN lists
            db.execute(delete(CodeVersion).where(CodeVersion.id.in_(doomed[start : start + 500])))
        removed += len(doomed)
    db.flush()
    return removed


def history_bytes(db: Db, user_id: str | None = None) -> int:
    """[B] every saved version's size: one student's, or everyone's."""
    query = select(func.coalesce(func.sum(CodeVersion.size_bytes), 0))
    if user_id is not None:
        query = query.where(CodeVersion.user_id == user_id)
    return int(db.scalar(query) or 0)


def oldest_kept(db: Db, user_id: str, workspace: str, filename: str) -> int | None:
    """The oldest version of a file still kept (None when none is)."""
    return db.scalar(
        select(func.min(CodeVersion.version)).where(
            CodeVersion.user_id == user_id,
            CodeVersion.workspace == workspace,
            CodeVersion.filename == filename,
        )
    )


def versions(db: Db, user_id: str, workspace: str, filename: str) -> list[CodeVersion]:
    return list(
        db.scalars(
            select(CodeVersion)
            .where(
                CodeVersion.user_id == user_id,
                CodeVersion.workspace == workspace,
                CodeVersion.filename == filename,
            )
            .order_by(CodeVersion.version.desc())
            .limit(MAX_VERSIONS_LISTED)
        )
    )


def get_version(
    db: Db, user_id: str, workspace: str, filename: str, version: int
) -> CodeVersion | None:
    return db.scalar(
        select(CodeVersion).where(
            CodeVersion.user_id == user_id,
            CodeVersion.workspace == workspace,
            CodeVersion.filename == filename,
            CodeVersion.version == version,
        )
    )


def delete_file(db: Db, user_id: str, workspace: str, filename: str) -> int:
    """Remove a file with its history (the student asked to); returns the versions removed."""
    result = db.execute(
        delete(CodeVersion).where(
            CodeVersion.user_id == user_id,
            CodeVersion.workspace == workspace,
            CodeVersion.filename == filename,
        )
    )
    return result.rowcount or 0
