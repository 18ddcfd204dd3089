"""What each sensor measured, as geometry for the view (the view draws it in the robot frame): a
ranger's cone (its axis and edges, as long as the reading), a scan's hit points (LiDAR, the depth
camera's slice).

Drawn from the messages themselves, placed by the sensor frames of /tf, so a replay draws them as
the live view does: a `sensor_msgs/Range` becomes a cone of its `field_of_view`, a
`sensor_msgs/LaserScan` the points at its valid ranges (REP 117: a range outside
[range_min, range_max], NaN or inf is no return). A message without a frame (the CrowBot's
`Distance`, std_msgs/Int32 in cm) is drawn by its simulated sensor's own `rays()`
(server/sim/sensors/base.py `DrawsRays`) at the robot's pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from sandbox.msgs import get_message_class
from server.sim.robots.base import RobotModel
from server.sim.sensors.base import SenseContext, Sensor
from server.sim.state import Pose2D, RobotState
from server.sim.world import World
from server.viz.view_state import SensorFrame, ViewState

ULTRASOUND, INFRARED = 0, 1  # sensor_msgs/Range radiation_type
ROBOT_ORIGIN = (0.0, 0.0, 0.0)  # drawings are made in the robot frame


@dataclass(frozen=True, slots=True)
class SensorDrawing:
    """One sensor's reading in the world: `segments` (K, 4) rows x1, y1, x2, y2 [m] and scan
    `points` (P, 2) [m]; `kind` picks the colour ("ultrasound", "infrared", "scan")."""

    kind: str
    segments: np.ndarray
    points: np.ndarray


def static_frame(mount: tuple[float, ...]) -> SensorFrame:
    """A robot's declared frame (x, y, yaw[, roll]) as a SensorFrame (roll pi flips it)."""
    roll = mount[3] if len(mount) == 4 else 0.0  # R = Rz(yaw) Rx(roll): x axis stays at yaw
    return SensorFrame(mount[0], mount[1], mount[2], -1.0 if math.cos(roll) < 0 else 1.0)


def _origin(pose: tuple[float, float, float], frame: SensorFrame) -> tuple[float, float, float]:
    """World x, y [m] of the frame's origin and the world heading of the robot."""
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    return x + c * frame.x - s * frame.y, y + s * frame.x + c * frame.y, yaw


def range_cone(pose, frame: SensorFrame, msg: dict[str, Any]) -> np.ndarray:
    """(3, 4) segments: the cone's right edge, axis and left edge, as long as the reading (the
    maximum range when nothing answered)."""
    reading = msg["range"]
    length = msg["max_range"] if reading is None or not math.isfinite(reading) else reading
    length = min(max(float(length), 0.0), float(msg["max_range"]))
    ox, oy, yaw = _origin(pose, frame)
    half = 0.5 * float(msg["field_of_view"])
    directions = yaw + np.array(
        [frame.direction(-half), frame.direction(0.0), frame.direction(half)]
    )
    return np.column_stack(
        [
            np.full(3, ox),
            np.full(3, oy),
            ox + length * np.cos(directions),
            oy + length * np.sin(directions),
        ]
    )


def scan_points(pose, frame: SensorFrame, msg: dict[str, Any]) -> np.ndarray:
    """(P, 2) world points of a LaserScan's valid returns."""
    ranges = np.array([np.nan if r is None else r for r in msg["ranges"]], dtype=np.float64)
    angles = msg["angle_min"] + msg["angle_increment"] * np.arange(len(ranges))
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(ranges) & (ranges >= msg["range_min"]) & (ranges <= msg["range_max"])
    ox, oy, yaw = _origin(pose, frame)
    directions = yaw + frame.heading + frame.sign * angles[valid]
    return np.column_stack(
        [ox + ranges[valid] * np.cos(directions), oy + ranges[valid] * np.sin(directions)]
    )


def _frame_of(state: ViewState, robot: RobotModel, msg: dict[str, Any]) -> SensorFrame | None:
    frame_id = msg.get("header", {}).get("frame_id")
    if frame_id in state.sensor_frames:
        return state.sensor_frames[frame_id]
    if frame_id in robot.frames:
        return static_frame(robot.frames[frame_id])
    if frame_id == "base_link":
        return SensorFrame(0.0, 0.0, 0.0, 1.0)
    return None


def _own_rays(
    sensor: Sensor, type_name: str, msg: dict[str, Any], pose, world: World
) -> np.ndarray | None:
    """The simulated sensor's rays() for a flat message (std_msgs), at `pose`."""
    if not hasattr(sensor, "rays") or not type_name.startswith("std_msgs/"):
        return None
    message = get_message_class(type_name)(**msg)
    state = RobotState(pose=Pose2D(*pose))
    context = SenseContext(world, None, state, 0.0, world.lights)  # rays() never casts
    return np.asarray(sensor.rays(context, message), dtype=np.float64).reshape(-1, 4)


def reading_key(state: ViewState, robot: RobotModel, msg: dict[str, Any]) -> tuple:
    """What a reading's drawing depends on: the message itself and where its frame sits (a
    servo turns the IR ranger's). Compared with `is`/`==` to skip redrawing what has not changed;
    holding the message keeps its identity from being reused."""
    header = msg.get("header") if isinstance(msg, dict) else None
    frame_id = header.get("frame_id") if isinstance(header, dict) else None
    return (msg, state.sensor_frames.get(frame_id) if frame_id else None)


def sensor_drawings(
    state: ViewState,
    robot: RobotModel,
    sensors: dict[str, Sensor],
    world: World,
    topics: set[str] | None = None,
) -> dict[str, SensorDrawing]:
    """Topic -> what to draw IN THE ROBOT FRAME (x forward, y left [m]), for every sensor reading
    in `state` that can be drawn (only `topics`, if given). Drawn below the robot's node, a
    reading moves with the robot for free and is sent again only when a new message comes."""
    empty_points, empty_segments = np.zeros((0, 2)), np.zeros((0, 4))
    drawings = {}
    for topic, (type_name, msg) in state.latest.items():
        if topics is not None and topic not in topics:
            continue
        try:
            if type_name == "sensor_msgs/LaserScan":
                frame = _frame_of(state, robot, msg)
                if frame is not None:
                    points = scan_points(ROBOT_ORIGIN, frame, msg)
                    drawings[topic] = SensorDrawing("scan", empty_segments, points)
            elif type_name == "sensor_msgs/Range":
                frame = _frame_of(state, robot, msg)
                if frame is not None:
                    kind = "infrared" if msg["radiation_type"] == INFRARED else "ultrasound"
                    cone = range_cone(ROBOT_ORIGIN, frame, msg)
                    drawings[topic] = SensorDrawing(kind, cone, empty_points)
            elif topic in sensors:
                segments = _own_rays(sensors[topic], type_name, msg, ROBOT_ORIGIN, world)
                if segments is not None:
                    drawings[topic] = SensorDrawing("ultrasound", segments, empty_points)
        except (KeyError, TypeError, ValueError, AttributeError):
            continue  # a message we cannot draw is left out, never an error in the view
    return drawings
