"""Instructor admin API, courses: create, list, look at and delete them, enrol students, set
the exercises, and download the grade book as CSV. Students get 404 for every route here.

Enrolling and setting exercises are PUT/DELETE on the membership itself, so repeating one is
harmless: the answer says whether anything changed.
"""

from __future__ import annotations

import csv
import io
import re

from fastapi import APIRouter, Depends, HTTPException, Query, Request
from fastapi.responses import Response
from pydantic import BaseModel, ConfigDict, Field

from server.api.auth import instructor
from server.api.routes.admin_exercises import find_buildable
from server.api.routes.runs import iso
from server.store import accounts, courses
from server.store.courses import CourseNameTakenError
from server.store.models import Course

router = APIRouter(prefix="/api/admin", tags=["admin"], dependencies=[Depends(instructor)])
GRADES_HEADER = (
    "student_id",
    "student_name",
    "email",
    "exercise",
    "best_score",
    "attempts",
    "best_run_id",
    "best_run_url",
)
# A spreadsheet runs a cell that starts with one of these as a formula (CSV injection, OWASP):
# names come from people, so such a cell gets a leading apostrophe, as spreadsheets do.
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


class CourseCreate(BaseModel):
    model_config = ConfigDict(extra="forbid")

    name: str = Field(
        min_length=1,
        max_length=120,
        pattern=r"^[^\x00-\x1f\x7f]+$",  # no control characters (PostgreSQL refuses NUL)
        description="unique, e.g. 'Robotics 101'",
    )


def _course(db, course_id: str) -> Course:
    course = courses.get(db, course_id)
    if course is None:
        raise HTTPException(
            404, f"no course '{course_id}'; GET /api/admin/courses lists the courses and their ids"
        )
    return course


def course_out(db, course: Course, detail: bool = False) -> dict:
    out = {
        "id": course.id,
        "name": course.name,
        "created_at": iso(course.created_at),
        "exercises": courses.exercises(db, course.id),
    }
    if detail:
        out["students"] = [
            {"id": u.id, "name": u.name, "email": u.email, "role": u.role, "disabled": u.disabled}
            for u in courses.members(db, course.id)
        ]
    else:
        out["student_count"] = courses.member_count(db, course.id)
    return out


@router.post("/courses", status_code=201, summary="Create a course (names are unique)")
def create_course(body: CourseCreate, request: Request) -> dict:
    name = body.name.strip()
    if not name:
        raise HTTPException(422, "a course needs a name that is not only spaces")
    try:
        with request.app.state.store.session() as db:
            return course_out(db, courses.create(db, name), detail=True)
    except CourseNameTakenError as error:
        raise HTTPException(409, str(error)) from None


@router.get("/courses", summary="Every course, with its exercises and number of students")
def list_courses(request: Request) -> dict:
    with request.app.state.store.session() as db:
        return {"courses": [course_out(db, c) for c in courses.list_courses(db)]}


@router.get("/courses/{course_id}", summary="One course, with its students and exercises")
def get_course(course_id: str, request: Request) -> dict:
    with request.app.state.store.session() as db:
        return course_out(db, _course(db, course_id), detail=True)


@router.delete("/courses/{course_id}", summary="Delete a course (its students and runs stay)")
def delete_course(course_id: str, request: Request) -> dict:
    with request.app.state.store.session() as db:
        _course(db, course_id)
        courses.delete_course(db, course_id)
    return {"ok": True, "id": course_id, "action": "delete"}


def _membership(request: Request, course_id: str, user_id: str, enrolled: bool) -> dict:
    with request.app.state.store.session() as db:
        _course(db, course_id)
        if accounts.get_user(db, user_id) is None:
            raise HTTPException(
                404, f"no user '{user_id}'; GET /api/admin/users lists the users and their ids"
            )
        if enrolled:
            changed = courses.enrol(db, course_id, user_id)
        else:
            changed = courses.unenrol(db, course_id, user_id)
    return {"course": course_id, "user": user_id, "enrolled": enrolled, "changed": changed}


@router.put("/courses/{course_id}/students/{user_id}", summary="Enrol a user (idempotent)")
def enrol(course_id: str, user_id: str, request: Request) -> dict:
    return _membership(request, course_id, user_id, True)


@router.delete("/courses/{course_id}/students/{user_id}", summary="Unenrol a user")
def unenrol(course_id: str, user_id: str, request: Request) -> dict:
    return _membership(request, course_id, user_id, False)


@router.put(
    "/courses/{course_id}/exercises/{exercise_id}", summary="Set an exercise for the course"
)
def add_exercise(course_id: str, exercise_id: str, request: Request) -> dict:
    with request.app.state.store.session() as db:
        _course(db, course_id)
        find_buildable(db, exercise_id)  # UnknownIdError: 404 with the valid ids
        changed = courses.set_exercise(db, course_id, exercise_id, True)
        listed = courses.exercises(db, course_id)
    return {"course": course_id, "exercise": exercise_id, "changed": changed, "exercises": listed}


@router.delete(
    "/courses/{course_id}/exercises/{exercise_id}", summary="Take an exercise off the course"
)
def remove_exercise(course_id: str, exercise_id: str, request: Request) -> dict:
    # No check that the exercise exists: a deleted custom exercise can still be taken off.
    with request.app.state.store.session() as db:
        _course(db, course_id)
        changed = courses.set_exercise(db, course_id, exercise_id, False)
        listed = courses.exercises(db, course_id)
    return {"course": course_id, "exercise": exercise_id, "changed": changed, "exercises": listed}


def _cell(value: object) -> str:
    if value is None:
        return ""
    text = str(value)
    return "'" + text if text.startswith(FORMULA_STARTS) else text


def _file_stem(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_-]+", "-", name).strip("-") or "course"


@router.get(
    "/grades.csv",
    summary="The grade book: best score, attempts and best run per student and exercise",
    response_class=Response,
    responses={200: {"content": {"text/csv": {}}}},
)
def grades_csv(
    request: Request,
    course: str | None = Query(
        None, max_length=64, description="a course id; without it, every student"
    ),
) -> Response:
    base_url = request.app.state.settings.base_url()
    with request.app.state.store.session() as db:
        stem = "grades"
        if course is not None:
            stem = f"grades-{_file_stem(_course(db, course).name)}"
        rows = courses.grades(db, course)
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\r\n")  # RFC 4180 line ends
    writer.writerow(GRADES_HEADER)
    for row in rows:
        writer.writerow(
            (
                row.user_id,
                _cell(row.name),
                _cell(row.email),
                _cell(row.exercise_id),
                "" if row.best_score is None else f"{row.best_score:g}",
                row.attempts,
                row.best_run_id or "",
                f"{base_url}/api/runs/{row.best_run_id}" if row.best_run_id else "",
            )
        )
    return Response(
        out.getvalue(),
        media_type="text/csv; charset=utf-8",
        headers={"Content-Disposition": f'attachment; filename="{stem}.csv"'},
    )
