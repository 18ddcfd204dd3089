"""Instructor admin API, exercises: every exercise with what only instructors see (the built-in
ones' reference solutions), custom exercises made, edited and deleted, and a try run of any
exercise as the instructor. Students get 404 for every route here.

A custom exercise starts from a built-in one (`template`, changing text, starter code, duration
and thresholds) or from scratch (robot, world, starter code, duration, generic checks).
`server.service.exercises.validate` decides what a definition may say; this module turns its
refusals into answers and stores what it accepts.
"""

from __future__ import annotations

import time
from typing import Annotated, Literal

from fastapi import APIRouter, Depends, HTTPException, Request
from pydantic import Field
from sqlalchemy import select
from sqlalchemy.exc import IntegrityError

from server.api.auth import Caller, instructor
from server.api.routes.runs import iso, run_out
from server.api.schemas import HARD_CODE_CAP, ID_PATTERN, NAME_PATTERN, Strict
from server.exercises.registry import exercise_ids
from server.service import catalog, exercises
from server.service.catalog import ExerciseEntry, UnknownIdError, registry_entry
from server.service.exercises import ExerciseDefinitionError
from server.service.runs import RunRequest, node_spec
from server.store.models import CustomExercise

router = APIRouter(prefix="/api/admin", tags=["admin"], dependencies=[Depends(instructor)])
EXERCISE_ID_PATTERN = r"^[a-z][a-z0-9_]{2,63}$"  # also a workspace name and a file stem
CHECK_NAME_PATTERN = r"^[A-Za-z][A-Za-z0-9_]{0,63}$"
MAX_STARTER_FILES = 8  # as many nodes as a run may have
MAX_CHECKS = 16
MAX_SEEDS = 16
SEED = Annotated[int, Field(ge=0, le=2**31 - 1)]


class StarterFile(Strict):
    name: str = Field(pattern=NAME_PATTERN, description="node name, as in a launch file")
    code: str = Field(max_length=HARD_CODE_CAP, description="Python source")


class CheckThreshold(Strict):
    name: str = Field(
        pattern=CHECK_NAME_PATTERN,
        description="a check of the template, or a generic check (GET /api/admin/exercises)",
    )
    threshold: float = Field(allow_inf_nan=False)


class ExerciseFields(Strict):
    title: str | None = Field(None, min_length=1, max_length=120)
    description: str | None = Field(None, max_length=8000)
    template: str | None = Field(None, pattern=ID_PATTERN, description="a built-in exercise id")
    robot: str | None = Field(None, pattern=ID_PATTERN, description="without a template")
    world: str | None = Field(None, pattern=ID_PATTERN, description="without a template")
    starter: list[StarterFile] = Field(default_factory=list, max_length=MAX_STARTER_FILES)
    duration_s: float | None = Field(None, gt=0, description="[s] of robot time")
    clock: Literal["lockstep", "realtime"] | None = Field(None, description="without a template")
    checks: list[CheckThreshold] = Field(default_factory=list, max_length=MAX_CHECKS)
    seeds: list[SEED] | None = Field(
        None, min_length=1, max_length=MAX_SEEDS, description="without a template"
    )
    hardware_gate: bool | None = Field(
        None, description="a real-robot run needs this code to have finished in simulation"
    )


class ExerciseCreate(ExerciseFields):
    id: str = Field(
        pattern=EXERCISE_ID_PATTERN, description="lower case, digits and _; 3 to 64 characters"
    )


# ------------------------------------------------------------------------------ answers
def _files(exercise_files, exercise) -> list[dict]:
    out = []
    for name, relative in exercise_files:
        path = exercise.code_path(relative)
        out.append({"name": name, "filename": path.name, "code": path.read_text("utf-8")})
    return out


def exercise_out(entry: ExerciseEntry, row: CustomExercise | None = None) -> dict:
    """An exercise as an instructor sees it: the student's view, the seeds, and the reference
    solution (built-in) or who made it and from what (custom)."""
    out = catalog.describe(entry)
    out["seeds"] = list(entry.exercise.seeds)
    out["hardware_gate"] = entry.exercise.hardware_gate
    if row is None:
        out["reference"] = _files(entry.exercise.reference, entry.exercise)
    else:
        out["template"] = row.definition.get("template")
        out["created_by"] = row.created_by
        out["created_at"] = iso(row.created_at)
        out["updated_at"] = iso(row.updated_at)
    return out


def _broken_out(row: CustomExercise, error: Exception) -> dict:
    """A stored definition that no longer builds (its template is gone): shown, not hidden."""
    return {
        "id": row.id,
        "title": row.definition.get("title"),
        "custom": True,
        "template": row.definition.get("template"),
        "error": f"{error}; edit it (PUT /api/admin/exercises/{row.id}) or delete it",
    }


# ------------------------------------------------------------------------------ checking
def _definition(exercise_id: str, body: ExerciseFields, settings) -> dict:
    """The definition a body describes, checked by our rules and then by the service's."""
    definition = {"id": exercise_id, **body.model_dump(exclude_none=True)}
    _refuse_duplicates("starter", [node["name"] for node in definition["starter"]], "node")
    _refuse_duplicates("checks", [check["name"] for check in definition["checks"]], "check")
    for node in definition["starter"]:
        size = len(node["code"].encode())
        if size > settings.max_code_bytes_per_file:
            raise HTTPException(
                422,
                f"starter node '{node['name']}' has {size} bytes of code; the limit per file is "
                f"{settings.max_code_bytes_per_file} bytes",
            )
    duration = definition.get("duration_s")
    if duration is not None and duration > settings.max_run_duration_s:
        raise HTTPException(
            422,
            f"duration_s {duration:g} s is longer than this lab allows for a run "
            f"({settings.max_run_duration_s:g} s); choose a shorter one",
        )
    template_id = definition.get("template")
    if template_id:
        template = registry_entry(template_id)
        if template is None:
            raise UnknownIdError("exercise", template_id, exercise_ids())
        for key in ("robot", "world"):
            given, used = definition.get(key), getattr(template.exercise, key)
            if given not in (None, used):
                raise HTTPException(
                    422,
                    f"exercise '{template_id}' uses {key} '{used}'; leave {key} out of an "
                    f"exercise made from it, or make one from scratch (without 'template')",
                )
        for key in ("clock", "seeds"):
            if key in definition:
                raise HTTPException(
                    422,
                    f"an exercise made from a template takes its {key} from it ('{template_id}'); "
                    f"leave {key} out, or make one from scratch (without 'template')",
                )
    try:
        return exercises.validate(definition)
    except ExerciseDefinitionError as error:
        raise HTTPException(422, str(error)) from None


def _refuse_duplicates(field: str, names: list[str], kind: str) -> None:
    seen = set()
    for name in names:
        if name in seen:
            raise HTTPException(
                422, f"{field}: {kind} '{name}' is listed twice; give each {kind} once"
            )
        seen.add(name)


def find_buildable(db, exercise_id: str) -> ExerciseEntry:
    """The exercise (UnknownIdError: 404), or 409 when its stored definition no longer builds."""
    try:
        return exercises.find(db, exercise_id)
    except ExerciseDefinitionError as error:
        raise HTTPException(
            409,
            f"custom exercise '{exercise_id}' cannot be used: {error}; edit it "
            f"(PUT /api/admin/exercises/{exercise_id}) or delete it",
        ) from None


def _custom_row(db, exercise_id: str, action: str) -> CustomExercise:
    """The stored custom exercise, or the answer that says why there is none to `action`."""
    if exercise_id in exercise_ids():
        raise HTTPException(
            409,
            f"'{exercise_id}' is a built-in exercise and cannot be {action}; create a custom one "
            f'from it instead: POST /api/admin/exercises with "template": "{exercise_id}"',
        )
    row = db.get(CustomExercise, exercise_id)
    if row is None:
        custom_ids = list(db.scalars(select(CustomExercise.id).order_by(CustomExercise.id)))
        if not custom_ids:
            raise HTTPException(
                404,
                f"no custom exercise '{exercise_id}'; there are none yet: create one with "
                "POST /api/admin/exercises",
            )
        raise UnknownIdError("custom exercise", exercise_id, custom_ids)
    return row


# ------------------------------------------------------------------------------ routes
@router.get("/exercises", summary="Every exercise, with reference code for the built-in ones")
def list_exercises(request: Request) -> dict:
    out = [exercise_out(entry) for entry in catalog.registry_entries()]
    with request.app.state.store.session() as db:
        for row in db.scalars(select(CustomExercise).order_by(CustomExercise.id)):
            try:
                out.append(exercise_out(exercises.build(row.definition), row))
            except ExerciseDefinitionError as error:
                out.append(_broken_out(row, error))
    generic = [
        {"name": name, "description": description, "unit": unit, "comparison": str(comparison)}
        for name, (description, unit, comparison, _) in exercises.GENERIC_CHECKS.items()
    ]
    return {"exercises": out, "generic_checks": generic}


@router.get("/exercises/{exercise_id}", summary="One exercise, as an instructor sees it")
def get_exercise(exercise_id: str, request: Request) -> dict:
    with request.app.state.store.session() as db:
        try:
            entry = exercises.find(db, exercise_id)
        except ExerciseDefinitionError as error:
            return _broken_out(db.get(CustomExercise, exercise_id), error)
        return exercise_out(entry, db.get(CustomExercise, exercise_id) if entry.custom else None)


@router.post("/exercises", status_code=201, summary="Create a custom exercise")
def create_exercise(
    body: ExerciseCreate, request: Request, caller: Caller = Depends(instructor)
) -> dict:
    if body.id in exercise_ids():
        raise HTTPException(
            409,
            f"'{body.id}' is a built-in exercise; choose another id (to start from it, give "
            f'"template": "{body.id}")',
        )
    definition = _definition(body.id, body, request.app.state.settings)
    conflict = (
        f"exercise '{body.id}' exists already; edit it with PUT /api/admin/exercises/{body.id} "
        "or choose another id"
    )
    try:
        with request.app.state.store.session() as db:
            if db.get(CustomExercise, body.id) is not None:
                raise HTTPException(409, conflict)
            now = time.time()
            row = CustomExercise(
                id=body.id,
                definition=definition,
                created_by=caller.id,
                created_at=now,
                updated_at=now,
            )
            db.add(row)
            db.flush()
            return exercise_out(exercises.build(definition), row)
    except IntegrityError:  # made by another request a moment ago
        raise HTTPException(409, conflict) from None


@router.put("/exercises/{exercise_id}", summary="Replace a custom exercise's definition")
def edit_exercise(exercise_id: str, body: ExerciseFields, request: Request) -> dict:
    with request.app.state.store.session() as db:
        row = _custom_row(db, exercise_id, "edited")
        definition = _definition(exercise_id, body, request.app.state.settings)
        row.definition = definition  # a new dict, so the JSON column is written
        row.updated_at = time.time()
        db.flush()
        return exercise_out(exercises.build(definition), row)


@router.delete("/exercises/{exercise_id}", summary="Delete a custom exercise (its runs stay)")
def delete_exercise(exercise_id: str, request: Request) -> dict:
    with request.app.state.store.session() as db:
        db.delete(_custom_row(db, exercise_id, "deleted"))
    return {"ok": True, "id": exercise_id, "action": "delete"}


@router.post(
    "/exercises/{exercise_id}/try",
    status_code=201,
    summary="Run an exercise as yourself: the reference solution (built-in) or the starter code",
)
def try_exercise(exercise_id: str, request: Request, caller: Caller = Depends(instructor)) -> dict:
    with request.app.state.store.session() as db:
        entry = find_buildable(db, exercise_id)
    if entry.custom:
        nodes = tuple(node_spec(name, code) for name, _, code in entry.starter)
        code = "starter"
    else:
        exercise = entry.exercise
        nodes = tuple(node_spec(f["name"], f["code"]) for f in _files(exercise.reference, exercise))
        code = "reference"
    service = request.app.state.runs
    record = service.start(
        caller.id,
        RunRequest(
            robot=None,
            world=None,
            exercise=entry,
            nodes=nodes,
            clock=None,
            duration_s=None,
            seed=None,
        ),
    )
    return {**run_out(record, service), "tried": code}
