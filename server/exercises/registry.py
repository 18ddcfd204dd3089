"""Exercises by id, validated like robots and worlds."""

from __future__ import annotations

import pickle

from server.exercises.crop_rover import EXERCISES as CROP_ROVER
from server.exercises.crowbot import EXERCISES as CROWBOT
from server.exercises.ir_scout import EXERCISES as IR_SCOUT
from server.exercises.model import Exercise
from server.exercises.turtlebot import EXERCISES as TURTLEBOT
from server.runs.spec import RunSpecError
from server.sim import load_world, robot_ids, world_ids

_EXERCISES: dict[str, Exercise] = {
    exercise.id: exercise for exercise in (*CROP_ROVER, *CROWBOT, *IR_SCOUT, *TURTLEBOT)
}


class UnknownExerciseError(ValueError):
    pass


def exercise_ids() -> tuple[str, ...]:
    return tuple(sorted(_EXERCISES))


def get_exercise(exercise_id: str) -> Exercise:
    exercise = _EXERCISES.get(exercise_id)
    if exercise is None:
        raise UnknownExerciseError(
            f"unknown exercise '{exercise_id}'; valid exercise ids: {', '.join(exercise_ids())}"
        )
    return exercise


def validate_exercise(exercise: Exercise) -> list[str]:
    """Problems with a registry entry, as sentences."""
    from server.exercises.grading import reference_nodes, run_spec, starter_nodes

    problems = []
    where = f"exercise '{exercise.id}'"
    if exercise.robot not in robot_ids():
        problems.append(f"{where}: unknown robot '{exercise.robot}'")
    if exercise.world not in world_ids():
        problems.append(f"{where}: unknown world '{exercise.world}'")
    elif exercise.robot not in load_world(exercise.world).robots:
        problems.append(f"{where}: robot '{exercise.robot}' is not meant for '{exercise.world}'")
    if not exercise.checks:
        problems.append(f"{where}: has no checks")
    if not exercise.seeds:
        problems.append(f"{where}: has no seeds")
    names = [check.name for check in exercise.checks]
    if len(set(names)) != len(names):
        problems.append(f"{where}: two checks share a name")
    if exercise.leaderboard_check is not None and exercise.key_check() is None:
        problems.append(
            f"{where}: leaderboard_check '{exercise.leaderboard_check}' is none of its checks "
            f"({', '.join(names)})"
        )
    try:
        pickle.dumps(exercise)  # `robodojo check` sends it to its worker processes
    except (pickle.PicklingError, TypeError, AttributeError) as error:
        problems.append(
            f"{where}: cannot be sent to a grading worker process (each check's metric must be "
            f"a module-level function, not a lambda or a closure): {error}"
        )
    for label, files in (("reference", exercise.reference), ("starter", exercise.starter)):
        if not files:
            problems.append(f"{where}: has no {label} code")
        for _, path in files:
            if not exercise.code_path(path).is_file():
                problems.append(f"{where}: {label} file '{path}' is missing")
    if not problems:
        try:
            for nodes in (reference_nodes(exercise), starter_nodes(exercise)):
                run_spec(exercise, nodes, exercise.seeds[0]).validate()
        except RunSpecError as error:
            problems.append(f"{where}: {error}")
    return problems
