"""What the 3D view shows at one instant, folded from a run's messages: the same fold serves a live
run (telemetry frames) and a replay (a recording's messages decoded the same way), so both views
draw identically.

Messages arrive as `server.service.decode` gives them: plain dicts (NaN as None). What is taken:
- `tf` (tf2_msgs/TFMessage): map -> base_link is the true pose; base_link -> <frame> places each
  sensor (the IR ranger's frame turns with the servo);
- `Leds` (std_msgs/Int32MultiArray [r, g, b]) and `Buzzer` (std_msgs/Bool, sounds BUZZER_TONE_S);
- a nav_msgs/Path (the planner's `plan`), the goal (`goal`, `goal_pose`), a student's `lookahead`
  point (geometry_msgs/PointStamped or PoseStamped) if a node publishes one;
- everything else as the latest message per topic (the sensors' rays are drawn from these).
Pure: no viser, no clock; the trail is bounded (TRAIL_POINTS_KEPT).
"""

from __future__ import annotations

import contextlib
import math
from collections import deque
from dataclasses import dataclass, field
from typing import Any

from server.sim.robots.crowbot import BUZZER_TONE_S
from server.sim.world import LightSource

TRAIL_STEP_M = 0.01  # [m] a trail point every centimetre moved: smooth at any zoom
TRAIL_POINTS_KEPT = 20_000  # 200 m of trail; older points drop off the end
GOAL_TOPICS = ("goal", "goal_pose")
LOOKAHEAD_TOPIC = "lookahead"
ROBOT_FRAME, WORLD_FRAME = "base_link", "map"


@dataclass(frozen=True, slots=True)
class SensorFrame:
    """A sensor frame in the robot frame: origin x, y [m], the heading of its x axis [rad], and
    `sign` +1 when its angles grow counter-clockwise (ROS convention) or -1 when the frame is
    mounted upside down (the crop rover's lidar: robot direction = heading - angle)."""

    x: float
    y: float
    heading: float
    sign: float

    def direction(self, angle_rad: float) -> float:
        """Robot-frame direction [rad] of a beam at `angle_rad` in this frame."""
        return self.heading + self.sign * angle_rad


def frame_from_transform(transform: dict[str, Any]) -> SensorFrame:
    """A geometry_msgs/Transform (as a dict) projected onto the floor plane."""
    t, q = transform["translation"], transform["rotation"]
    w, x, y, z = q["w"], q["x"], q["y"], q["z"]
    # First column and the z-z entry of the rotation matrix of the unit quaternion.
    r00, r10 = 1 - 2 * (y * y + z * z), 2 * (x * y + w * z)
    r22 = 1 - 2 * (x * x + y * y)
    return SensorFrame(t["x"], t["y"], math.atan2(r10, r00), 1.0 if r22 >= 0 else -1.0)


def _yaw(orientation: dict[str, Any]) -> float:
    return frame_from_transform({"translation": {"x": 0, "y": 0}, "rotation": orientation}).heading


@dataclass
class ViewState:
    """The latest of everything drawn. `apply()` folds one message in; `lights` is set by the
    source (a live run's lights move; a replay shows the world's)."""

    time_s: float = 0.0  # [s] run time of the newest message
    pose: tuple[float, float, float] | None = None  # x [m], y [m], yaw [rad]
    sensor_frames: dict[str, SensorFrame] = field(default_factory=dict)
    leds_rgb: tuple[int, int, int] | None = None
    buzzer_until_s: float = -math.inf
    plan: list[tuple[float, float]] | None = None
    goal: tuple[float, float, float] | None = None
    lookahead: tuple[float, float] | None = None
    latest: dict[str, tuple[str, dict[str, Any]]] = field(default_factory=dict)
    trail: deque[tuple[float, float]] = field(
        default_factory=lambda: deque(maxlen=TRAIL_POINTS_KEPT)
    )
    lights: tuple[LightSource, ...] = ()
    version: int = 0  # bumped by every apply(): a drawer skips a state it has drawn

    @property
    def buzzer_on(self) -> bool:
        return self.time_s < self.buzzer_until_s

    def apply(self, topic: str, type_name: str, time_s: float, msg: dict[str, Any]) -> None:
        """Fold one decoded message in; a malformed one is ignored (the view shows what it can).
        A ROS 2 type ("nav_msgs/msg/Path") is drawn as its ROS 1 twin: the fields drawn (poses,
        frames, ranges) have the same names in both."""
        if not isinstance(msg, dict):
            return
        if "/msg/" in type_name:
            type_name = type_name.replace("/msg/", "/", 1)
        self.version += 1
        self.time_s = max(self.time_s, float(time_s))
        with contextlib.suppress(KeyError, TypeError, ValueError, IndexError):
            self._apply(topic, type_name, float(time_s), msg)

    def _apply(self, topic: str, type_name: str, time_s: float, msg: dict[str, Any]) -> None:
        if type_name == "tf2_msgs/TFMessage":
            for stamped in msg["transforms"]:
                parent, child = stamped["header"]["frame_id"], stamped["child_frame_id"]
                if parent == WORLD_FRAME and child == ROBOT_FRAME:
                    frame = frame_from_transform(stamped["transform"])
                    self._move(frame.x, frame.y, frame.heading)
                elif parent == ROBOT_FRAME:
                    self.sensor_frames[child] = frame_from_transform(stamped["transform"])
        elif topic == "Leds" and type_name == "std_msgs/Int32MultiArray":
            data = msg["data"]
            if len(data) == 3 and all(isinstance(v, int) and 0 <= v <= 255 for v in data):
                self.leds_rgb = (data[0], data[1], data[2])
        elif topic == "Buzzer" and type_name == "std_msgs/Bool":
            self.buzzer_until_s = time_s + BUZZER_TONE_S if msg["data"] else -math.inf
        elif type_name == "nav_msgs/Path":
            self.plan = [
                (p["pose"]["position"]["x"], p["pose"]["position"]["y"]) for p in msg["poses"]
            ]
        elif topic in GOAL_TOPICS and type_name == "geometry_msgs/PoseStamped":
            pose = msg["pose"]
            self.goal = (pose["position"]["x"], pose["position"]["y"], _yaw(pose["orientation"]))
        elif topic == LOOKAHEAD_TOPIC and type_name == "geometry_msgs/PointStamped":
            self.lookahead = (msg["point"]["x"], msg["point"]["y"])
        elif topic == LOOKAHEAD_TOPIC and type_name == "geometry_msgs/PoseStamped":
            self.lookahead = (msg["pose"]["position"]["x"], msg["pose"]["position"]["y"])
        else:
            self.latest[topic] = (type_name, msg)

    def _move(self, x: float, y: float, yaw: float) -> None:
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            return
        self.pose = (x, y, yaw)
        if not self.trail or math.hypot(x - self.trail[-1][0], y - self.trail[-1][1]) >= (
            TRAIL_STEP_M
        ):
            self.trail.append((x, y))
