"""Students' code: a workspace per exercise (or per robot, for free play), a file per node,
every save a new version. Restoring an old version saves it again as the newest, so history
only grows and nothing is lost."""

from __future__ import annotations

import time

from sqlalchemy import delete, func, select
from sqlalchemy.orm import Session as Db

from server.store.models import CodeVersion

MAX_VERSIONS_LISTED = 200  # the newest this many versions of a file are listed


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


def save(db: Db, user_id: str, workspace: str, filename: str, code: str) -> CodeVersion:
    """A new version, unless the code is the same as the newest (autosave saves often)."""
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
    )
    db.add(version)
    db.flush()
    return version


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
