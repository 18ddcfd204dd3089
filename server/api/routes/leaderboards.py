"""Leaderboards: per course and exercise, each student's best graded run, ranked by score, then
the exercise's key figure (its `leaderboard_check`), then the earlier run.

A student sees the courses they are enrolled in and their boards, with names or pseudonyms as the
instructor chose and their own entry marked; a hidden board, or another course's, is 404. An
instructor sees every board (hidden ones too, with names and pseudonyms side by side), shows or
hides it, switches names and pseudonyms, and resets it: runs created before the reset no longer
count on the board (the grade book still counts them).
"""

from __future__ import annotations

import time

from fastapi import APIRouter, Depends, HTTPException, Request
from pydantic import BaseModel, ConfigDict

from server.api.auth import Caller, current_user, instructor
from server.api.routes.runs import iso
from server.exercises.model import Comparison
from server.service import exercises
from server.store import courses, leaderboards
from server.store.leaderboards import BoardSettings, KeyFigure, NameMode
from server.store.models import Course

router = APIRouter(prefix="/api/courses", tags=["leaderboards"])


class BoardSettingsUpdate(BaseModel):
    model_config = ConfigDict(extra="forbid")

    visible: bool | None = None  # False: students get 404 for the board
    names: NameMode | None = None  # "names" | "pseudonyms"


def _my_course(db, caller: Caller, course_id: str) -> Course:
    """The course, if the caller may see it: an instructor any, a student their own (another
    course is answered exactly like one that does not exist)."""
    course = courses.get(db, course_id)
    if course is not None and (caller.is_instructor or courses.is_member(db, course_id, caller.id)):
        return course
    raise HTTPException(
        404, f"no course '{course_id}' of yours; GET /api/courses lists the courses you are in"
    )


def _exercise(db, course: Course, exercise_id: str):
    """The exercise, if the course has it: one it sets, or any when it sets none."""
    listed = courses.exercises(db, course.id)
    if listed and exercise_id not in listed:
        raise HTTPException(
            404,
            f"exercise '{exercise_id}' is not set for course '{course.name}'; its exercises: "
            f"{', '.join(listed)}",
        )
    return exercises.find(db, exercise_id).exercise  # UnknownIdError: 404 with the valid ids


def _course_and_exercise(db, caller: Caller, course_id: str, exercise_id: str):
    """The course the caller may see and the exercise of it a board is about (404s as above)."""
    course = _my_course(db, caller, course_id)
    return course, _exercise(db, course, exercise_id)


def _settings_out(board: BoardSettings) -> dict:
    return {"visible": board.visible, "names": str(board.names), "reset_at": iso(board.reset_at)}


def _board(db, caller: Caller, course: Course, exercise, board: BoardSettings) -> dict:
    check = exercise.key_check()
    key = None
    key_out = None
    if check is not None:
        lower = check.comparison is Comparison.AT_MOST
        key = KeyFigure(check.name, lower_is_better=lower)
        key_out = {
            "check": check.name,
            "description": check.description,
            "unit": check.unit,
            "better": "lower" if lower else "higher",
        }
    entries = leaderboards.board(db, course.id, exercise.id, key, since=board.reset_at)
    secret = leaderboards.lab_secret(db)
    rows = []
    mine = None
    for entry in entries:
        alias = leaderboards.pseudonym(secret, course.id, entry.user_id)
        row = {
            "rank": entry.rank,
            "name": entry.name if board.names is NameMode.NAMES else alias,
            "score": round(entry.score, 3),
            "key_value": entry.key_value,
            "achieved_at": iso(entry.run_created_at),
            "you": entry.user_id == caller.id,
        }
        if caller.is_instructor:  # who is who, and the run to open
            row.update(
                user_id=entry.user_id, real_name=entry.name, pseudonym=alias, run_id=entry.run_id
            )
        if row["you"]:
            mine = {"rank": entry.rank, "of": len(entries), "name": row["name"]}
        rows.append(row)
    out = {
        "course": course.id,
        "course_name": course.name,
        "exercise": exercise.id,
        "title": exercise.title,
        **_settings_out(board),
        "key_figure": key_out,
        "entries": rows,
        "you": mine,
    }
    if board.reset_at is not None:
        out["note"] = f"reset {iso(board.reset_at)}: only runs started since then count"
    return out


@router.get("", summary="The courses you can see leaderboards of, with their exercises")
def my_courses(request: Request, caller: Caller = Depends(current_user)) -> dict:
    with request.app.state.store.session() as db:
        if caller.is_instructor:
            listed = courses.list_courses(db)
        else:
            listed = courses.courses_of(db, caller.id)
        return {
            "courses": [
                {"id": c.id, "name": c.name, "exercises": courses.exercises(db, c.id)}
                for c in listed
            ]
        }


@router.get(
    "/{course_id}/leaderboards/{exercise_id}",
    summary="An exercise's leaderboard in a course: best graded run per student, ranked",
)
def get_board(
    course_id: str, exercise_id: str, request: Request, caller: Caller = Depends(current_user)
) -> dict:
    with request.app.state.store.session() as db:
        course, exercise = _course_and_exercise(db, caller, course_id, exercise_id)
        board = leaderboards.settings(db, course.id, exercise.id)
        if not board.visible and not caller.is_instructor:
            raise HTTPException(
                404,
                f"the leaderboard of '{exercise.title}' in '{course.name}' is hidden by the "
                "instructor; your runs are still graded",
            )
        return _board(db, caller, course, exercise, board)


@router.put(
    "/{course_id}/leaderboards/{exercise_id}/settings",
    summary="Show or hide a leaderboard, and choose names or pseudonyms (instructors)",
)
def put_settings(
    course_id: str,
    exercise_id: str,
    body: BoardSettingsUpdate,
    request: Request,
    caller: Caller = Depends(instructor),
) -> dict:
    with request.app.state.store.session() as db:
        course, exercise = _course_and_exercise(db, caller, course_id, exercise_id)
        board = leaderboards.set_settings(db, course.id, exercise.id, body.visible, body.names)
        return {"course": course.id, "exercise": exercise.id, **_settings_out(board)}


@router.post(
    "/{course_id}/leaderboards/{exercise_id}/reset",
    summary="Start a leaderboard afresh: runs created before now no longer count (instructors)",
)
def reset_board(
    course_id: str, exercise_id: str, request: Request, caller: Caller = Depends(instructor)
) -> dict:
    with request.app.state.store.session() as db:
        course, exercise = _course_and_exercise(db, caller, course_id, exercise_id)
        board = leaderboards.reset(db, course.id, exercise.id, time.time())
        return {
            "course": course.id,
            "exercise": exercise.id,
            **_settings_out(board),
            "message": (
                f"the leaderboard of '{exercise.title}' in '{course.name}' starts afresh: runs "
                f"started before {iso(board.reset_at)} no longer count on it (they stay in the "
                "grade book)"
            ),
        }
