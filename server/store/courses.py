"""Courses: a named group of students and the exercises set for them, and the grade book drawn
from their runs.

    course = create(db, "Robotics 101")
    enrol(db, course.id, student.id)            # idempotent
    set_exercise(db, course.id, "crowbot_distance_pid", True)
    for row in grades(db, course.id): ...      # best score per student and exercise

A grade is the best score of the student's finished runs of the exercise, the run that got it
(the earliest, on a tie) and how many runs of it the student started in all.
"""

from __future__ import annotations

import time
import uuid
from dataclasses import dataclass

from sqlalchemy import delete, func, select
from sqlalchemy.exc import IntegrityError
from sqlalchemy.orm import Session as Db

from server.runs.state import RunState
from server.store.accounts import Role
from server.store.models import (
    Course,
    CourseExercise,
    Enrolment,
    LeaderboardSetting,
    RunRecord,
    User,
)


class CourseNameTakenError(ValueError):
    """Course names are unique; the message names the course that has it."""

    def __init__(self, name: str, existing_id: str | None) -> None:
        where = f" (id {existing_id})" if existing_id else ""
        super().__init__(f"a course named '{name}' exists already{where}; choose another name")
        self.existing_id = existing_id


def get(db: Db, course_id: str) -> Course | None:
    return db.get(Course, course_id)


def by_name(db: Db, name: str) -> Course | None:
    return db.scalar(select(Course).where(Course.name == name))


def create(db: Db, name: str) -> Course:
    existing = by_name(db, name)
    if existing is not None:
        raise CourseNameTakenError(name, existing.id)
    course = Course(id=uuid.uuid4().hex, name=name, created_at=time.time())
    db.add(course)
    try:
        db.flush()
    except IntegrityError:  # another instructor took the name a moment ago; the caller rolls back
        raise CourseNameTakenError(name, None) from None
    return course


def list_courses(db: Db) -> list[Course]:
    return list(db.scalars(select(Course).order_by(Course.name)))


def delete_course(db: Db, course_id: str) -> bool:
    """False when there is no such course. Enrolments, the exercise list and the leaderboard
    settings go with it."""
    course = get(db, course_id)
    if course is None:
        return False
    # Explicit, not left to ON DELETE CASCADE: SQLite enforces it only with foreign_keys=ON.
    db.execute(delete(Enrolment).where(Enrolment.course_id == course_id))
    db.execute(delete(CourseExercise).where(CourseExercise.course_id == course_id))
    db.execute(delete(LeaderboardSetting).where(LeaderboardSetting.course_id == course_id))
    db.delete(course)
    db.flush()
    return True


def enrol(db: Db, course_id: str, user_id: str) -> bool:
    """Enrol a user (the course and user must exist); False when already enrolled."""
    if db.get(Enrolment, (course_id, user_id)) is not None:
        return False
    db.add(Enrolment(course_id=course_id, user_id=user_id))
    db.flush()
    return True


def unenrol(db: Db, course_id: str, user_id: str) -> bool:
    """False when the user was not enrolled."""
    result = db.execute(
        delete(Enrolment).where(Enrolment.course_id == course_id, Enrolment.user_id == user_id)
    )
    return bool(result.rowcount)


def members(db: Db, course_id: str) -> list[User]:
    """Everyone enrolled, by name."""
    return list(
        db.scalars(
            select(User)
            .join(Enrolment, Enrolment.user_id == User.id)
            .where(Enrolment.course_id == course_id)
            .order_by(User.name, User.id)
        )
    )


def is_member(db: Db, course_id: str, user_id: str) -> bool:
    return db.get(Enrolment, (course_id, user_id)) is not None


def courses_of(db: Db, user_id: str) -> list[Course]:
    """The courses a user is enrolled in, by name."""
    return list(
        db.scalars(
            select(Course)
            .join(Enrolment, Enrolment.course_id == Course.id)
            .where(Enrolment.user_id == user_id)
            .order_by(Course.name)
        )
    )


def member_count(db: Db, course_id: str) -> int:
    query = select(func.count()).select_from(Enrolment).where(Enrolment.course_id == course_id)
    return db.scalar(query) or 0


def exercises(db: Db, course_id: str) -> list[str]:
    """The ids of the exercises set for the course, sorted."""
    return list(
        db.scalars(
            select(CourseExercise.exercise_id)
            .where(CourseExercise.course_id == course_id)
            .order_by(CourseExercise.exercise_id)
        )
    )


def set_exercise(db: Db, course_id: str, exercise_id: str, included: bool) -> bool:
    """Add (included=True) or remove an exercise; False when nothing changed."""
    present = db.get(CourseExercise, (course_id, exercise_id)) is not None
    if present == included:
        return False
    if included:
        db.add(CourseExercise(course_id=course_id, exercise_id=exercise_id))
    else:
        db.execute(
            delete(CourseExercise).where(
                CourseExercise.course_id == course_id, CourseExercise.exercise_id == exercise_id
            )
        )
    db.flush()
    return True


@dataclass(frozen=True, slots=True)
class Grade:
    """One student's standing on one exercise."""

    user_id: str
    name: str
    email: str | None
    exercise_id: str
    best_score: float | None  # 0..1; None: no finished, scored run yet
    best_run_id: str | None
    attempts: int  # runs of the exercise started, whatever became of them


def grades(db: Db, course_id: str | None = None) -> list[Grade]:
    """A grade per student and exercise, students by name, exercises by id.

    With a course: its enrolled students, and the exercises set for it (or, when none are set,
    every exercise a member has a scored run of). Without one: every student, and every
    exercise any of them has a scored run of.
    """
    if course_id is None:
        students = list(
            db.scalars(
                select(User).where(User.role == str(Role.STUDENT)).order_by(User.name, User.id)
            )
        )
        set_for_course: list[str] = []
    else:
        students = [u for u in members(db, course_id) if u.role == str(Role.STUDENT)]
        set_for_course = exercises(db, course_id)
    if not students:
        return []
    runs = db.execute(
        select(
            RunRecord.user_id,
            RunRecord.exercise_id,
            RunRecord.id,
            RunRecord.state,
            RunRecord.score,
        )
        .where(
            RunRecord.user_id.in_([s.id for s in students]),
            RunRecord.exercise_id.is_not(None),
        )
        .order_by(RunRecord.created_at, RunRecord.id)
    ).all()
    exercise_ids = set_for_course or sorted({r.exercise_id for r in runs if r.score is not None})
    wanted = set(exercise_ids)
    attempts: dict[tuple[str, str], int] = {}
    best: dict[tuple[str, str], tuple[float, str]] = {}
    finished = str(RunState.FINISHED)
    for run in runs:
        if run.exercise_id not in wanted:
            continue
        key = (run.user_id, run.exercise_id)
        attempts[key] = attempts.get(key, 0) + 1
        if run.state != finished or run.score is None:
            continue
        # Runs come oldest first and only a higher score replaces: the first to reach it wins.
        if key not in best or run.score > best[key][0]:
            best[key] = (run.score, run.id)
    rows = []
    for student in students:
        for exercise_id in exercise_ids:
            key = (student.id, exercise_id)
            score, run_id = best.get(key, (None, None))
            rows.append(
                Grade(
                    user_id=student.id,
                    name=student.name,
                    email=student.email,
                    exercise_id=exercise_id,
                    best_score=score,
                    best_run_id=run_id,
                    attempts=attempts.get(key, 0),
                )
            )
    return rows
