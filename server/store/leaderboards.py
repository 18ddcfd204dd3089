"""Leaderboards: per course and exercise, each enrolled student's best graded run, ranked.

    key = KeyFigure("settling_time", lower_is_better=True)
    for entry in board(db, course_id, "crowbot_distance_pid", key): ...
    set_settings(db, course_id, exercise_id, visible=False)   # students get 404
    reset(db, course_id, exercise_id, time.time())             # older runs stop counting

A graded run is what the grade book (courses.grades) counts: a finished run of the exercise with
a score; a board ranks simulated runs only (a real robot's figures come from other conditions
and a queue for the robot: the grade book keeps them, the sim-vs-real report compares them). A
student's best is the highest score, then the better key figure (the exercise's
`leaderboard_check`, in its check's direction), then the earlier run; the board is ordered the
same way, so ranks are 1..n without ties. A run with no value for the key figure (the robot never
settled) is behind every run with one at the same score.

Pseudonyms are stable per student and course and say nothing about the name: an HMAC of the
course and user ids under the lab's own secret (made once, kept in lab_settings) picks two words
and a number.
"""

from __future__ import annotations

import hashlib
import hmac
import math
import secrets
import time
from dataclasses import dataclass
from enum import StrEnum

from sqlalchemy import select
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Session as Db

from server.runs.state import RunState
from server.store.accounts import Role
from server.store.models import (
    Enrolment,
    LabSetting,
    LeaderboardSetting,
    RunRecord,
    User,
)

SECRET_KEY = "leaderboard_secret"  # lab_settings key
SECRET_BYTES = 32  # [B] HMAC-SHA256 key

# Two words and a number: 32 x 32 x 100 = 102,400 pseudonyms, so two students of a class of 40
# share one with a chance of ~0.8 % (birthday bound); the board still tells them apart by rank.
ADJECTIVES = (
    "Amber", "Brisk", "Calm", "Clever", "Cosmic", "Daring", "Eager", "Fearless",
    "Gentle", "Glowing", "Humble", "Keen", "Lively", "Lucky", "Mellow", "Nimble",
    "Noble", "Patient", "Plucky", "Quick", "Quiet", "Rapid", "Silent", "Smooth",
    "Snappy", "Steady", "Sunny", "Swift", "Tidy", "Vivid", "Witty", "Zesty",
)  # fmt: skip
NOUNS = (
    "Albatross", "Badger", "Beaver", "Bison", "Condor", "Coyote", "Crane", "Dolphin",
    "Falcon", "Ferret", "Gecko", "Heron", "Ibex", "Jackal", "Kestrel", "Lemur",
    "Lynx", "Marmot", "Narwhal", "Ocelot", "Osprey", "Otter", "Panda", "Puffin",
    "Quokka", "Raven", "Salamander", "Stoat", "Tapir", "Walrus", "Wombat", "Yak",
)  # fmt: skip
PSEUDONYM_NUMBERS = 100


class NameMode(StrEnum):
    NAMES = "names"
    PSEUDONYMS = "pseudonyms"


@dataclass(frozen=True, slots=True)
class BoardSettings:
    visible: bool = True
    names: NameMode = NameMode.PSEUDONYMS  # who is who is the instructor's choice to share
    reset_at: float | None = None  # [s] epoch; runs created before it do not count


@dataclass(frozen=True, slots=True)
class KeyFigure:
    """The check that ranks equal scores, and its direction."""

    check: str
    lower_is_better: bool


@dataclass(frozen=True, slots=True)
class Entry:
    rank: int  # 1 = best
    user_id: str
    name: str
    score: float  # 0..1
    key_value: float | None  # the key figure of the run; None: none, or not a finite value
    run_id: str
    run_created_at: float  # [s] epoch


def settings(db: Db, course_id: str, exercise_id: str) -> BoardSettings:
    row = db.get(LeaderboardSetting, (course_id, exercise_id))
    if row is None:
        return BoardSettings()
    return BoardSettings(row.visible, NameMode(row.names), row.reset_at)


def _row(db: Db, course_id: str, exercise_id: str) -> LeaderboardSetting:
    row = db.get(LeaderboardSetting, (course_id, exercise_id))
    if row is None:
        defaults = BoardSettings()
        row = LeaderboardSetting(
            course_id=course_id,
            exercise_id=exercise_id,
            visible=defaults.visible,
            names=str(defaults.names),
            reset_at=defaults.reset_at,
            updated_at=time.time(),
        )
        db.add(row)
    return row


def set_settings(
    db: Db,
    course_id: str,
    exercise_id: str,
    visible: bool | None = None,
    names: NameMode | None = None,
) -> BoardSettings:
    """Change what is given (None: leave it); the course must exist."""
    row = _row(db, course_id, exercise_id)
    if visible is not None:
        row.visible = visible
    if names is not None:
        row.names = str(names)
    row.updated_at = time.time()
    db.flush()
    return settings(db, course_id, exercise_id)


def reset(db: Db, course_id: str, exercise_id: str, at: float) -> BoardSettings:
    """From now on only runs created at or after `at` [s] count; the runs stay (grade book)."""
    row = _row(db, course_id, exercise_id)
    row.reset_at = at
    row.updated_at = time.time()
    db.flush()
    return settings(db, course_id, exercise_id)


def _key_value(checks: list | None, key: KeyFigure | None) -> float | None:
    if key is None:
        return None
    for check in checks or ():
        if isinstance(check, dict) and check.get("name") == key.check:
            value = check.get("value")
            if isinstance(value, int | float) and math.isfinite(value):
                return float(value)
            return None
    return None


def _order(score: float, value: float | None, key: KeyFigure | None, created_at: float, run_id):
    """Sort key, best first: score, then the key figure (missing last), then the earlier run."""
    if key is None or value is None:
        return (-score, math.inf, created_at, run_id)
    return (-score, value if key.lower_is_better else -value, created_at, run_id)


def board(
    db: Db,
    course_id: str,
    exercise_id: str,
    key: KeyFigure | None,
    since: float | None = None,
) -> list[Entry]:
    """The enrolled students with a graded run of the exercise created at or after `since`,
    each by their best run, best first."""
    query = (
        select(
            RunRecord.id,
            RunRecord.user_id,
            RunRecord.score,
            RunRecord.checks,
            RunRecord.created_at,
            User.name,
        )
        .join(User, User.id == RunRecord.user_id)
        .join(Enrolment, Enrolment.user_id == RunRecord.user_id)
        .where(
            Enrolment.course_id == course_id,
            User.role == str(Role.STUDENT),
            RunRecord.exercise_id == exercise_id,
            RunRecord.state == str(RunState.FINISHED),
            RunRecord.score.is_not(None),
            RunRecord.hardware.is_(None),  # simulated runs only (see the module docstring)
        )
    )
    if since is not None:
        query = query.where(RunRecord.created_at >= since)
    best: dict[str, tuple[tuple, Entry]] = {}
    for run in db.execute(query):
        value = _key_value(run.checks, key)
        order = _order(run.score, value, key, run.created_at, run.id)
        if run.user_id in best and best[run.user_id][0] <= order:
            continue
        entry = Entry(0, run.user_id, run.name, run.score, value, run.id, run.created_at)
        best[run.user_id] = (order, entry)
    ranked = sorted(best.values(), key=lambda pair: pair[0])
    return [
        Entry(rank, e.user_id, e.name, e.score, e.key_value, e.run_id, e.run_created_at)
        for rank, (_, e) in enumerate(ranked, start=1)
    ]


def lab_secret(db: Db) -> bytes:
    """The lab's pseudonym key, made on first use. Two servers making it at once: one insert
    wins, the other reads it (a savepoint keeps the caller's transaction usable)."""
    row = db.get(LabSetting, SECRET_KEY)
    if row is None:
        try:
            with db.begin_nested():
                db.add(
                    LabSetting(
                        key=SECRET_KEY,
                        value={"value": secrets.token_hex(SECRET_BYTES)},
                        updated_at=time.time(),
                    )
                )
        except IntegrityError:
            pass
        row = db.get(LabSetting, SECRET_KEY, populate_existing=True)
    assert row is not None
    return bytes.fromhex(row.value["value"])


def pseudonym(secret: bytes, course_id: str, user_id: str) -> str:
    """'Swift Heron 17': the same for a student in a course, different across courses."""
    digest = hmac.new(secret, f"{course_id}/{user_id}".encode(), hashlib.sha256).digest()
    number = int.from_bytes(digest[2:4], "big") % PSEUDONYM_NUMBERS
    return f"{ADJECTIVES[digest[0] % len(ADJECTIVES)]} {NOUNS[digest[1] % len(NOUNS)]} {number}"
