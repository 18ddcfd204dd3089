"""The robots on the lab bench (the inventory): what instructors register, read by the hardware
service to match a connecting robot and to set its safety limits."""

from __future__ import annotations

import time
import uuid

from sqlalchemy import select
from sqlalchemy.orm import Session as Db

from server.store.models import RobotEntry


def add(db: Db, **fields) -> RobotEntry:
    entry = RobotEntry(id=uuid.uuid4().hex, created_at=time.time(), in_service=True, **fields)
    db.add(entry)
    db.flush()
    return entry


def listing(db: Db) -> list[RobotEntry]:
    return list(db.scalars(select(RobotEntry).order_by(RobotEntry.name)))


def by_name(db: Db, name: str) -> RobotEntry | None:
    return db.scalar(select(RobotEntry).where(RobotEntry.name == name))


def by_address(db: Db, transport: str, address: str) -> RobotEntry | None:
    return db.scalar(
        select(RobotEntry).where(RobotEntry.transport == transport, RobotEntry.address == address)
    )


def names(db: Db) -> str:
    """The registered names, for a sentence about an unknown one."""
    return ", ".join(e.name for e in listing(db)) or "none registered"


def remove(db: Db, entry: RobotEntry) -> None:
    db.delete(entry)
    db.flush()
