"""Validators for robot models and worlds, like Gymnasium's `check_env`: run them on a new or
edited definition before anyone drives it, and the tests run them over every registered entry.

    check_robot(get_robot("crowbot"))      # or check_robot("crowbot")
    check_world(load_world("office"))      # or check_world("office")

Each raises `DefinitionError` (a `WorldError` for worlds, as loading one does) listing every
problem found, one sentence each, naming the field and what a sound value looks like;
`robot_problems` and `world_problems` return the same sentences as a list. They check what the
simulator assumes without checking again at run time:

- a robot: sizes and speed limits positive; every sensor topic publishes a ROS message type at a
  finite positive rate, with a phase inside its period and a description; every command topic
  names a message class that builds with no arguments, and `apply_command` either acts on that
  empty message or refuses it with `CommandError` (anything else is a bug in the model); topic
  names are ROS names, none both published and subscribed; the motor model resets and steps to
  finite wheel speeds; sensor frames are (x, y, yaw[, roll]) of finite numbers below base_link,
  and every frame a sensor stamps exists.
- a world: arrays of the documented shapes, finite; heights, radii and tape widths positive;
  bounds a real rectangle; at least one spawn, names unique, each inside the bounds with room for
  the body of every robot the world declares (its body disc, offset as the model says); lights,
  tape and their values in range; known robot ids; a map whose cells match its size.
"""

from __future__ import annotations

import math
import re

import numpy as np

from server.sim.registry import UnknownRobotError, get_robot, robot_ids, robots_for_world
from server.sim.robots.base import CommandError, RobotModel
from server.sim.state import RobotState
from server.sim.world import KNOWN_ROBOT_IDS, World, WorldError, load_world, world_ids

__all__ = [
    "DefinitionError",
    "WorldDefinitionError",
    "check_robot",
    "check_world",
    "registry_problems",
    "robot_problems",
    "world_problems",
]

# The frames the run's /tf provides itself (server/runs/tf.py): sensor frames hang below
# base_link and may not reuse these names; a sensor may stamp its messages in any of them.
_RUN_FRAMES = ("map", "odom", "base_link")
_MOTOR_PROBE_S = 0.001  # [s] one physics tick at the default 1000 Hz
_ROS_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*(/[A-Za-z][A-Za-z0-9_]*)*$")


class DefinitionError(ValueError):
    """A robot model or world definition that the simulator cannot trust; the message lists
    every problem, one sentence each."""


def _positive(value: object) -> bool:
    return isinstance(value, (int, float)) and math.isfinite(value) and value > 0


class WorldDefinitionError(WorldError, DefinitionError):
    """A compiled world that fails `check_world`: a `WorldError`, as loading errors are."""


def _is_message_class(msg_type: object) -> bool:
    return isinstance(msg_type, type) and bool(getattr(msg_type, "_type", None))


# ----------------------------------------------------------------------------------- robots
def robot_problems(robot: RobotModel) -> list[str]:
    """What is wrong with the robot model, one sentence each (empty when it is sound)."""
    name = f"robot '{getattr(robot, 'id', type(robot).__name__)}'"
    problems: list[str] = []
    for attribute in ("id", "title", "source"):
        if not isinstance(getattr(robot, attribute, None), str) or not getattr(robot, attribute):
            problems.append(f"{name}: set `{attribute}` to a non-empty string")
    problems += _geometry_problems(robot, name)
    problems += _sensor_problems(robot, name)
    problems += _command_problems(robot, name)
    problems += _motor_problems(robot, name)
    problems += _frame_problems(robot, name)
    return problems


def _geometry_problems(robot: RobotModel, name: str) -> list[str]:
    problems = []
    g = robot.geometry
    for field in ("body_radius_m", "wheel_radius_m", "track_m", "length_m", "width_m", "height_m"):
        value = getattr(g, field)
        if not _positive(value):
            problems.append(f"{name}: geometry.{field} must be a positive size [m], got {value}")
    if not (math.isfinite(g.body_offset_x_m) and abs(g.body_offset_x_m) < g.body_radius_m):
        problems.append(
            f"{name}: geometry.body_offset_x_m must put the wheel axle inside the body "
            f"(|offset| < body_radius_m), got {g.body_offset_x_m}"
        )
    for field in ("max_linear_m_s", "max_angular_rad_s"):
        value = getattr(robot.limits, field)
        if not _positive(value):
            problems.append(f"{name}: limits.{field} must be a positive speed, got {value}")
    return problems


def _sensor_problems(robot: RobotModel, name: str) -> list[str]:
    problems = []
    sensors = robot.build_sensors()
    if not sensors:
        problems.append(f"{name}: publishes no sensor topics; build_sensors() returned none")
    for topic, sensor in sensors.items():
        where = f"{name}: sensor topic '{topic}'"
        if not _ROS_NAME.match(topic):
            problems.append(f"{where} is not a ROS name (letters, digits, _ and /)")
        rate_hz = getattr(sensor, "rate_hz", None)
        if not _positive(rate_hz):
            problems.append(f"{where} has rate {rate_hz} Hz; give a finite rate above 0")
        else:
            phase_s = getattr(sensor, "phase_s", None)
            if not (isinstance(phase_s, (int, float)) and 0 <= phase_s < 1.0 / rate_hz):
                problems.append(
                    f"{where} has phase {phase_s} s; it must lie in [0, {1.0 / rate_hz:g}) s, "
                    "within one period"
                )
        if not _is_message_class(getattr(sensor, "msg_type", None)):
            problems.append(f"{where}: msg_type must be a ROS message class (with a _type)")
        if not robot.sensor_descriptions.get(topic):
            problems.append(f"{where} has no description in sensor_descriptions")
    for topic in set(robot.sensor_descriptions) - set(sensors):
        problems.append(f"{name}: sensor_descriptions names '{topic}', which no sensor publishes")
    overlap = sorted(set(sensors) & set(robot.commands))
    if overlap:
        problems.append(f"{name}: topics both published and subscribed: {overlap}")
    return problems


def _command_problems(robot: RobotModel, name: str) -> list[str]:
    problems = []
    if not robot.commands:
        problems.append(f"{name}: subscribes to no command topics; declare them in `commands`")
    for topic, (msg_type, description) in robot.commands.items():
        where = f"{name}: command topic '{topic}'"
        if not _ROS_NAME.match(topic):
            problems.append(f"{where} is not a ROS name (letters, digits, _ and /)")
        if not description:
            problems.append(f"{where} has no description")
        if not _is_message_class(msg_type):
            problems.append(f"{where}: {msg_type!r} is not a ROS message class (with a _type)")
            continue
        try:
            message = msg_type()
        except Exception as error:
            problems.append(f"{where}: {msg_type._type}() does not build ({error})")
            continue
        try:
            robot.apply_command(topic, message, RobotState(), robot.build_motors(), 0.0)
        except CommandError:
            pass  # refusing an empty message with a sentence is fine (Leds wants [r, g, b])
        except Exception as error:
            problems.append(
                f"{where}: apply_command raised {type(error).__name__} ({error}) on an empty "
                f"{msg_type._type}; act on it or raise CommandError with a sentence"
            )
    return problems


def _motor_problems(robot: RobotModel, name: str) -> list[str]:
    try:
        motors = robot.build_motors()
        motors.reset()
        motors.command(robot.limits.max_linear_m_s, 0.0)
        speeds = motors.step(_MOTOR_PROBE_S)
    except Exception as error:
        return [f"{name}: the motor model fails to reset, command and step ({error!r})"]
    if len(speeds) != 2 or not all(math.isfinite(s) for s in speeds):
        return [f"{name}: motors.step must return (left, right) finite wheel speeds, got {speeds}"]
    return []


def _frame_problems(robot: RobotModel, name: str) -> list[str]:
    problems = []
    frames = robot.sensor_frames(RobotState())
    for frame, pose in frames.items():
        if frame in _RUN_FRAMES:
            problems.append(
                f"{name}: sensor frame '{frame}' is one the run provides; give the sensor a "
                "frame name of its own"
            )
        if len(pose) not in (3, 4) or not all(
            isinstance(v, (int, float)) and math.isfinite(v) for v in pose
        ):
            problems.append(
                f"{name}: sensor frame '{frame}' must be (x [m], y [m], yaw [rad]) or "
                f"(x, y, yaw, roll [rad]) of finite numbers, got {pose!r}"
            )
    known = set(frames) | set(_RUN_FRAMES)
    for topic, sensor in robot.build_sensors().items():
        for attribute in ("frame_id", "child_frame_id"):
            frame = getattr(sensor, attribute, None)
            if frame is not None and frame not in known:
                problems.append(
                    f"{name}: sensor topic '{topic}' stamps {attribute} '{frame}', which is not "
                    f"among its frames ({', '.join(sorted(known))}); add it to `frames`"
                )
    return problems


def check_robot(robot: RobotModel | str) -> None:
    """Raise `DefinitionError` listing every problem of the robot model (or registered id)."""
    model = get_robot(robot) if isinstance(robot, str) else robot
    problems = robot_problems(model)
    if problems:
        raise DefinitionError(_listing(f"robot '{model.id}'", problems))


# ----------------------------------------------------------------------------------- worlds
def world_problems(world: World) -> list[str]:
    """What is wrong with the compiled world, one sentence each (empty when it is sound)."""
    name = f"world '{world.id}'"
    problems = _array_problems(world, name)
    min_x, min_y, max_x, max_y = world.bounds
    if not (all(math.isfinite(v) for v in world.bounds) and min_x < max_x and min_y < max_y):
        problems.append(f"{name}: bounds {world.bounds} must be (min_x, min_y, max_x, max_y) [m]")
    problems += _spawn_problems(world, name)
    names = [light.name for light in world.lights]
    if len(set(names)) != len(names):
        problems.append(f"{name}: light names must be unique, got {names}")
    for light in world.lights:
        if not world.in_bounds(light.x, light.y):
            problems.append(f"{name}: light '{light.name}' at ({light.x}, {light.y}) is outside")
        if not (_positive(light.intensity) and math.isfinite(light.z) and light.z >= 0):
            problems.append(
                f"{name}: light '{light.name}' needs intensity > 0 and height z >= 0 [m], got "
                f"{light.intensity} and {light.z}"
            )
    if not all(world.in_bounds(x, y) for x, y in world.tape_segments.reshape(-1, 2)):
        problems.append(f"{name}: tape leaves the bounds")
    if (world.tape_width <= 0).any() or (
        (world.tape_darkness < 0) | (world.tape_darkness > 1)
    ).any():
        problems.append(f"{name}: tape widths must be > 0 [m] and darkness within [0, 1]")
    for field in ("ambient_light", "floor_reflectance"):
        value = getattr(world, field)
        if not 0.0 <= value <= 1.0:
            problems.append(f"{name}: {field} must lie within [0, 1], got {value}")
    if not world.robots:
        problems.append(f"{name}: declares no robots; list the robot ids it suits")
    problems += [
        f"{name}: unknown robot id '{r}' (known: {', '.join(KNOWN_ROBOT_IDS)})"
        for r in world.robots
        if r not in KNOWN_ROBOT_IDS
    ]
    grid = world.grid_map
    if grid is not None:
        if grid.data.shape != (grid.height, grid.width):
            problems.append(
                f"{name}: grid_map.data has shape {grid.data.shape}; its height and width say "
                f"({grid.height}, {grid.width})"
            )
        if not _positive(grid.resolution):
            problems.append(f"{name}: grid_map.resolution must be > 0 [m/cell]")
    return problems


def _array_problems(world: World, name: str) -> list[str]:
    problems = []
    shapes = {
        "segments": (world.segments, 4),
        "circles": (world.circles, 3),
        "tape_segments": (world.tape_segments, 4),
        "boxes": (world.boxes, 6),
    }
    for field, (array, columns) in shapes.items():
        if array.ndim != 2 or array.shape[1] != columns or not np.isfinite(array).all():
            problems.append(f"{name}: {field} must be a finite (N, {columns}) array")
    per_row = {
        "segment_height": len(world.segments),
        "circle_height": len(world.circles),
        "tape_width": len(world.tape_segments),
        "tape_darkness": len(world.tape_segments),
    }
    for field, rows in per_row.items():
        values = getattr(world, field)
        if values.shape != (rows,) or not np.isfinite(values).all():
            problems.append(f"{name}: {field} must hold one finite value per row ({rows})")
    if (world.segment_height <= 0).any() or (world.circle_height <= 0).any():
        problems.append(f"{name}: every wall, box and cylinder height must be > 0 [m]")
    if (world.circles[:, 2] <= 0).any():
        problems.append(f"{name}: every cylinder radius must be > 0 [m]")
    if world.circle_kind and len(world.circle_kind) != len(world.circles):
        problems.append(f"{name}: circle_kind must name one kind per cylinder")
    return problems


def _spawn_problems(world: World, name: str) -> list[str]:
    if not world.spawns:
        return [f"{name}: has no spawn; add at least one start pose"]
    problems = []
    names = [spawn.name for spawn in world.spawns]
    if len(set(names)) != len(names):
        problems.append(f"{name}: spawn names must be unique, got {names}")
    bodies = []
    for robot_id in world.robots:
        try:
            bodies.append((robot_id, get_robot(robot_id).geometry))
        except UnknownRobotError:
            continue  # reported with the robot ids
    for spawn in world.spawns:
        if not world.in_bounds(spawn.x, spawn.y):
            problems.append(f"{name}: spawn '{spawn.name}' at ({spawn.x}, {spawn.y}) is outside")
            continue
        for robot_id, geometry in bodies:
            # The body disc sits body_offset_x_m ahead of the pose (the point between the wheels).
            offset = geometry.body_offset_x_m
            cx = spawn.x + offset * math.cos(spawn.yaw)
            cy = spawn.y + offset * math.sin(spawn.yaw)
            gap = world.clearance(cx, cy)
            if gap < geometry.body_radius_m:
                problems.append(
                    f"{name}: spawn '{spawn.name}' leaves {gap:.3f} m around the body of "
                    f"'{robot_id}', which needs {geometry.body_radius_m:.3f} m; move the spawn "
                    "away from the walls"
                )
    return problems


def check_world(world: World | str) -> None:
    """Raise `WorldDefinitionError` (a `WorldError` and a `DefinitionError`) listing every
    problem of the world (or packaged world id)."""
    compiled = load_world(world) if isinstance(world, str) else world
    problems = world_problems(compiled)
    if problems:
        raise WorldDefinitionError(_listing(f"world '{compiled.id}'", problems))


def _listing(what: str, problems: list[str]) -> str:
    prefix = what + ": "
    lines = "\n".join(f"- {p.removeprefix(prefix)}" for p in problems)
    return f"{what} has {len(problems)} problem{'s' if len(problems) != 1 else ''}:\n{lines}"


# ----------------------------------------------------------------------------------- registry
def registry_problems() -> list[str]:
    """Problems across every registered robot and packaged world, and between them."""
    problems: list[str] = []
    for robot_id in robot_ids():
        problems += robot_problems(get_robot(robot_id))
        if not robots_for_world(robot_id):
            problems.append(f"robot '{robot_id}' has no world to drive in")
    for world_id in world_ids():
        problems += world_problems(load_world(world_id))
    return problems
