"""What students can pick: robots, worlds and exercises (the registry's and the ones instructors
made), each with what a client needs to show it. Starter code is part of an exercise; the
reference solution never leaves the server."""

from __future__ import annotations

from dataclasses import dataclass

from server.exercises.grading import cases_of
from server.exercises.model import Exercise
from server.exercises.registry import exercise_ids, get_exercise
from server.sim import get_robot, load_world, robot_ids, robots_for_world, world_ids


class UnknownIdError(LookupError):
    """An id that names nothing; the message lists the valid ids."""

    def __init__(self, kind: str, given: str, valid: list[str] | tuple[str, ...]) -> None:
        super().__init__(f"unknown {kind} '{given}'; valid {kind} ids: {', '.join(valid)}")
        self.kind = kind
        self.valid = list(valid)


@dataclass(frozen=True, slots=True)
class ExerciseEntry:
    exercise: Exercise
    starter: tuple[tuple[str, str, str], ...]  # (node name, file name, code)
    custom: bool = False


def robots() -> list[dict]:
    result = []
    for robot_id in robot_ids():
        robot = get_robot(robot_id)
        result.append(
            {
                "id": robot_id,
                "title": robot.title,
                "worlds": list(robots_for_world(robot_id)),
                "topics": [
                    {
                        "name": t.name,
                        "type": t.type_name,
                        "direction": str(t.direction),
                        "rate_hz": t.rate_hz,
                        "description": t.description,
                    }
                    for t in robot.topics()
                ],
            }
        )
    return result


def worlds() -> list[dict]:
    result = []
    for world_id in world_ids():
        world = load_world(world_id)
        result.append(
            {
                "id": world_id,
                "title": world.title,
                "robots": list(world.robots),
                "bounds": list(world.bounds),
                # Geometry for a top-down map [m]: walls and box edges as segments, boxes,
                # cylinders (plants, posts), floor tape, lights and the named start poses.
                "segments": _rounded(world.segments),
                "boxes": _rounded(world.boxes),
                "circles": [
                    [*_rounded(row), kind]
                    for row, kind in zip(
                        world.circles,
                        world.circle_kind or ("post",) * len(world.circles),
                        strict=False,
                    )
                ],
                "tape": [
                    [*_rounded(row), round(float(width), 4)]
                    for row, width in zip(world.tape_segments, world.tape_width, strict=True)
                ],
                "lights": [
                    {"name": light.name, "x": light.x, "y": light.y, "movable": light.movable}
                    for light in world.lights
                ],
                "spawns": [
                    {"name": spawn.name, "x": spawn.x, "y": spawn.y, "yaw": spawn.yaw}
                    for spawn in world.spawns
                ],
            }
        )
    return result


def _rounded(values) -> list:
    """A numpy row (or table of rows) as plain lists, to a tenth of a millimetre."""
    if getattr(values, "ndim", 1) == 2:
        return [_rounded(row) for row in values]
    return [round(float(v), 4) for v in values]


def check_robot(robot_id: str) -> None:
    if robot_id not in robot_ids():
        raise UnknownIdError("robot", robot_id, robot_ids())


def check_world(world_id: str) -> None:
    if world_id not in world_ids():
        raise UnknownIdError("world", world_id, world_ids())


def registry_entry(exercise_id: str) -> ExerciseEntry | None:
    if exercise_id not in exercise_ids():
        return None
    exercise = get_exercise(exercise_id)
    starter = tuple(
        (name, exercise.code_path(path).name, exercise.code_path(path).read_text("utf-8"))
        for name, path in exercise.starter
    )
    return ExerciseEntry(exercise, starter)


def registry_entries() -> list[ExerciseEntry]:
    return [entry for i in exercise_ids() if (entry := registry_entry(i)) is not None]


def describe(entry: ExerciseEntry) -> dict:
    """An exercise as a student sees it: no reference solution."""
    exercise = entry.exercise
    return {
        "id": exercise.id,
        "title": exercise.title,
        "robot": exercise.robot,
        "world": exercise.world,
        "source": exercise.source,
        "description": exercise.description,
        "duration_s": exercise.duration_s,
        "clock": str(exercise.clock),
        "custom": entry.custom,
        "builtin_nodes": list(exercise.builtin_nodes),
        # Its grading cases (seed, start pose), as `robodojo check` runs them: the page's
        # "Check all seeds" starts one run per case (POST /api/runs with `case`).
        "cases": [
            {"case": case.index, "seed": case.seed, "start": list(case.start or []) or None}
            for case in cases_of(exercise)
        ],
        # What its leaderboards rank equal scores by (None: by who got there first).
        "leaderboard_check": key.name if (key := exercise.key_check()) else None,
        "starter": [
            {"name": name, "filename": filename, "code": code}
            for name, filename, code in entry.starter
        ],
        "checks": [
            {
                "name": c.name,
                "description": c.description,
                "unit": c.unit,
                "comparison": str(c.comparison),
                "threshold": c.threshold,
            }
            for c in exercise.checks
        ],
    }
