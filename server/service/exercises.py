"""Exercises as the service sees them: the registry's (server/exercises) and the ones instructors
made, stored as a definition in the database and built into the same `Exercise` object.

A custom exercise is either a registry exercise as a template with changes (title, text, starter
code, duration, thresholds) or made from scratch: a robot, a world, starter code, a duration and
checks picked from the generic metrics below, each with a threshold.
"""

from __future__ import annotations

import dataclasses
import logging
import time

from sqlalchemy import select
from sqlalchemy.orm import Session as Db

from sandbox.protocol import Clock
from server.exercises.checks import collisions
from server.exercises.model import Check, Comparison, Exercise
from server.exercises.registry import exercise_ids
from server.service.catalog import (
    ExerciseEntry,
    UnknownIdError,
    check_robot,
    check_world,
    registry_entries,
    registry_entry,
)
from server.sim import load_world
from server.store.models import CustomExercise

log = logging.getLogger("robodojo.service")


def _metric(key: str):
    return lambda evidence: float(evidence.result.metrics[key])


# Checks any exercise can use: name -> (description, unit, comparison, metric).
GENERIC_CHECKS = {
    "collisions": ("times the robot touched an obstacle", "", Comparison.AT_MOST, collisions),
    "distance_travelled_m": (
        "distance the robot travelled",
        "m",
        Comparison.AT_LEAST,
        _metric("distance_travelled_m"),
    ),
    "time_out_of_bounds_s": (
        "time the robot spent outside the world's bounds",
        "s",
        Comparison.AT_MOST,
        _metric("time_out_of_bounds_s"),
    ),
}


class ExerciseDefinitionError(ValueError):
    """A custom exercise definition that cannot work; the message says what to change."""


def all_entries(db: Db) -> list[ExerciseEntry]:
    """Every exercise students can pick; a stored one that no longer builds (its template was
    removed) is left out and logged, not allowed to break the list for everyone."""
    entries = registry_entries()
    for row in db.scalars(select(CustomExercise).order_by(CustomExercise.id)):
        try:
            entries.append(build(row.definition))
        except (ExerciseDefinitionError, KeyError, ValueError, TypeError) as error:
            log.warning("custom exercise '%s' is left out: %s", row.id, error)
    return entries


def all_ids(db: Db) -> list[str]:
    return [*exercise_ids(), *db.scalars(select(CustomExercise.id).order_by(CustomExercise.id))]


def find(db: Db, exercise_id: str) -> ExerciseEntry:
    entry = registry_entry(exercise_id)
    if entry is not None:
        return entry
    row = db.get(CustomExercise, exercise_id)
    if row is None:
        raise UnknownIdError("exercise", exercise_id, all_ids(db))
    return build(row.definition)


def build(definition: dict) -> ExerciseEntry:
    """The Exercise a stored (already validated) definition describes."""
    template_id = definition.get("template")
    starter = tuple(
        (node["name"], f"{node['name']}.py", node["code"]) for node in definition["starter"]
    )
    thresholds = {c["name"]: float(c["threshold"]) for c in definition.get("checks", [])}
    if template_id:
        template = registry_entry(template_id)
        if template is None:
            raise ExerciseDefinitionError(f"template exercise '{template_id}' no longer exists")
        base = template.exercise
        checks = tuple(
            dataclasses.replace(c, threshold=thresholds.get(c.name, c.threshold))
            for c in base.checks
            if not thresholds or c.name in thresholds
        )
        exercise = dataclasses.replace(
            base,
            hardware_gate=bool(definition.get("hardware_gate", base.hardware_gate)),
            id=definition["id"],
            title=definition.get("title") or base.title,
            description=definition.get("description") or base.description,
            duration_s=float(definition.get("duration_s") or base.duration_s),
            checks=checks,
            source=f"{base.source} (custom, from {base.id})",
        )
        return ExerciseEntry(exercise, starter or template.starter, custom=True)
    checks = tuple(
        Check(
            name=name,
            description=GENERIC_CHECKS[name][0],
            unit=GENERIC_CHECKS[name][1],
            comparison=GENERIC_CHECKS[name][2],
            threshold=threshold,
            metric=GENERIC_CHECKS[name][3],
        )
        for name, threshold in thresholds.items()
    )
    exercise = Exercise(
        id=definition["id"],
        title=definition["title"],
        robot=definition["robot"],
        world=definition["world"],
        source="custom exercise",
        description=definition.get("description", ""),
        duration_s=float(definition["duration_s"]),
        checks=checks,
        reference=(),
        starter=(),
        seeds=tuple(definition.get("seeds") or (1,)),
        clock=Clock(definition.get("clock", "lockstep")),
        hardware_gate=bool(definition.get("hardware_gate", True)),
    )
    return ExerciseEntry(exercise, starter, custom=True)


def validate(definition: dict) -> dict:
    """Check a definition and fill what a template gives; raise ExerciseDefinitionError."""
    if definition["id"] in exercise_ids():
        raise ExerciseDefinitionError(
            f"'{definition['id']}' is a built-in exercise; choose another id"
        )
    template_id = definition.get("template")
    if template_id:
        template = registry_entry(template_id)
        if template is None:
            raise UnknownIdError("exercise", template_id, exercise_ids())
        known = {c.name for c in template.exercise.checks}
        where = f"exercise '{template_id}'"
    else:
        for key in ("robot", "world", "title", "duration_s"):
            if definition.get(key) in (None, ""):
                raise ExerciseDefinitionError(
                    f"an exercise without a template needs '{key}'; or give 'template' "
                    "to start from a built-in exercise"
                )
        check_robot(definition["robot"])
        check_world(definition["world"])
        if definition["robot"] not in load_world(definition["world"]).robots:
            raise ExerciseDefinitionError(
                f"robot '{definition['robot']}' cannot be placed in world '{definition['world']}'"
            )
        if not definition.get("starter"):
            raise ExerciseDefinitionError("an exercise needs starter code: starter=[{name, code}]")
        if not definition.get("checks"):
            raise ExerciseDefinitionError(
                f"an exercise needs at least one check; generic checks: {', '.join(GENERIC_CHECKS)}"
            )
        known = set(GENERIC_CHECKS)
        where = "the generic checks"
    for check in definition.get("checks", []):
        if check["name"] not in known:
            raise ExerciseDefinitionError(
                f"check '{check['name']}' is not one of {where}: {', '.join(sorted(known))}"
            )
    definition["updated_at"] = time.time()
    build(definition)  # anything else wrong shows up here
    return definition
