"""The robots' and exercises' facts in the guide, generated from the registries at build time
(`server.sim.registry`, `server.exercises.registry`): topics, types, directions, rates, frames,
limits, checks and thresholds are never typed into a page, so a page cannot drift from the code.
"""

from __future__ import annotations

import math

from server.exercises.registry import exercise_ids, get_exercise
from server.sim.registry import get_robot, robot_ids, robots_for_world


def _cell(text: object) -> str:
    return " ".join(str(text).split()).replace("|", "\\|") or "-"


def _number(value: float) -> str:
    return f"{value:.3g}"


def robot_markdown(robot_id: str) -> str:
    robot = get_robot(robot_id)
    geometry, limits = robot.geometry, robot.limits
    lines = [
        f"**{robot.title}** (`{robot.id}`). Modelled on: {robot.source}. "
        f"Worlds: {', '.join(f'`{w}`' for w in robots_for_world(robot_id))}.",
        "",
        "| topic | type | direction | rate [Hz] | what it carries |",
        "|---|---|---|---|---|",
    ]
    for topic in robot.topics():
        rate = _number(topic.rate_hz) if topic.rate_hz else "-"
        direction = "robot publishes" if topic.direction == "publish" else "robot subscribes"
        lines.append(
            f"| `{topic.name}` | `{topic.type_name}` | {direction} | {rate} | "
            f"{_cell(topic.description)} |"
        )
    lines += [
        "",
        f"Size: {_number(geometry.length_m)} m long, {_number(geometry.width_m)} m wide, "
        f"{_number(geometry.height_m)} m high; collision disc of radius "
        f"{_number(geometry.body_radius_m)} m; wheels of radius "
        f"{_number(geometry.wheel_radius_m)} m, {_number(geometry.track_m)} m apart. "
        f"Top speed {_number(limits.max_linear_m_s)} m/s, "
        f"top turn rate {_number(limits.max_angular_rad_s)} rad/s "
        f"({_number(math.degrees(limits.max_angular_rad_s))} deg/s).",
        "",
    ]
    if robot.frames:
        lines += [
            "Sensor frames under `base_link` (x forward, y left, yaw counter-clockwise; the run "
            "publishes them on `/tf`):",
            "",
            "| frame | x [m] | y [m] | yaw [deg] |",
            "|---|---|---|---|",
        ]
        for frame, pose in robot.frames.items():
            x_m, y_m, yaw_rad = pose[:3]
            lines.append(f"| `{frame}` | {x_m:.3f} | {y_m:.3f} | {math.degrees(yaw_rad):.0f} |")
        lines.append("")
    return "\n".join(lines)


def exercise_markdown(exercise_id: str) -> str:
    exercise = get_exercise(exercise_id)
    seeds = ", ".join(str(seed) for seed in exercise.seeds)
    starts = f"; {len(exercise.starts)} start poses" if exercise.starts else ""
    lines = [
        f"Robot `{exercise.robot}` in world `{exercise.world}`, {_number(exercise.duration_s)} s "
        f"of simulated time ({exercise.clock.value} clock), graded on seeds {seeds}{starts}. "
        f"Source: {exercise.source}.",
        "",
    ]
    key = exercise.key_check()
    if key is not None:
        better = "lower" if key.comparison.value == "<=" else "higher"
        lines += [
            f"On a leaderboard, equal scores are ranked by `{key.name}` ({better} is better).",
            "",
        ]
    if exercise.builtin_nodes:
        lines += [
            "Built-in nodes started beside yours: "
            + ", ".join(f"`{name}`" for name in exercise.builtin_nodes)
            + ".",
            "",
        ]
    lines += [
        "| check | passes when | measured as |",
        "|---|---|---|",
    ]
    for check in exercise.checks:
        unit = f" {check.unit}" if check.unit else ""
        lines.append(
            f"| `{check.name}` | {check.comparison.value} {check.threshold:g}{unit} | "
            f"{_cell(check.description)} |"
        )
    lines.append("")
    return "\n".join(lines)


def exercise_text(exercise_id: str) -> str:
    """What the student page shows as the exercise's text (its description), as a quote."""
    exercise = get_exercise(exercise_id)
    quoted = "\n".join(f"> {line}" if line else ">" for line in exercise.description.splitlines())
    return f"> **{exercise.title}**\n>\n{quoted}\n"


def generic_checks_markdown() -> str:
    from server.service.exercises import GENERIC_CHECKS

    lines = ["| check | measures | unit | passes when the value is |", "|---|---|---|---|"]
    for name, (description, unit, comparison, _) in GENERIC_CHECKS.items():
        lines.append(f"| `{name}` | {description} | {unit or '-'} | {comparison.value} threshold |")
    return "\n".join(lines) + "\n"


def grades_columns_markdown() -> str:
    from server.api.routes.admin_courses import GRADES_HEADER

    return ", ".join(f"`{column}`" for column in GRADES_HEADER) + ".\n"


def migrations_markdown() -> str:
    """The database migrations, in order, with the first paragraph of each one's docstring."""
    import ast
    from pathlib import Path

    from server.store.db import MIGRATIONS_DIR

    lines = ["| revision | what it changes |", "|---|---|"]
    for path in sorted((Path(MIGRATIONS_DIR) / "versions").glob("*.py")):
        doc = ast.get_docstring(ast.parse(path.read_text())) or ""
        summary = " ".join(doc.split("\n\n")[0].split())
        lines.append(f"| `{path.stem}` | {_cell(summary)} |")
    return "\n".join(lines) + "\n"


def all_robot_ids() -> tuple[str, ...]:
    return robot_ids()


def all_exercise_ids() -> tuple[str, ...]:
    return exercise_ids()
