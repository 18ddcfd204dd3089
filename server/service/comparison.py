"""Sim-vs-real: a hardware run beside the simulation run of the same code that passed its gate.

Two things are compared. The topics both runs have in common that a person can read as lines
(the distance, the commands, the command the safety layer applied, the pose where the run knows
it), each sampled on one time base from the run's start so the two runs overlay in one plot; and
the exercise's check values, side by side, with the gap said in a sentence ("settling time
14.5 s in simulation, 17.2 s on the robot: 2.7 s slower").

Samples are held until the next one (zero-order hold): a command or a sensor reading is a step,
not a ramp, and holding never invents a value between two that were measured. A series is None
before its first message and after its last one, so a run that ended early shows a gap.

Pure functions over recordings and stored check results: the API route reads the records.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mcap.exceptions import McapError
from mcap.reader import make_reader

from sandbox.msgs import get_message_class

STEP_S = 0.1  # [s] the common time base: 10 Hz, the rate of the lab's control loops
MAX_POINTS = 3000  # samples per series at most; a longer run gets a coarser step
HOLD_AFTER_LAST_S = 0.5  # [s] a series is held this long past its last message, then ends

SIMULATION = "simulation"
HARDWARE = "hardware"


@dataclass(frozen=True, slots=True)
class Field:
    """One number read out of a message: its name in the report, and its unit."""

    name: str
    unit: str
    read: Callable[[object], float]


TWIST = (
    Field("linear.x", "m/s", lambda m: m.linear.x),
    Field("angular.z", "rad/s", lambda m: m.angular.z),
)
# Message types whose fields are plotted, by type name without the ROS 2 "/msg/" (a ROS 2 run's
# messages have the same field names for these). Everything else (scans, images, LEDs) is left
# out: it is not a line in a plot.
FIELDS: dict[str, tuple[Field, ...]] = {
    "geometry_msgs/Twist": TWIST,
    "std_msgs/Int32": (Field("data", "", lambda m: m.data),),
    "std_msgs/Int16": (Field("data", "", lambda m: m.data),),
    "std_msgs/Float32": (Field("data", "", lambda m: m.data),),
    "std_msgs/Float64": (Field("data", "", lambda m: m.data),),
    "sensor_msgs/Range": (Field("range", "m", lambda m: m.range),),
    "nav_msgs/Odometry": (
        Field("x", "m", lambda m: m.pose.pose.position.x),
        Field("y", "m", lambda m: m.pose.pose.position.y),
    ),
}
# A number whose unit the message type does not say: the CrowBot's Distance is in [cm]
# (server/sim/robots/crowbot.py).
TOPIC_UNITS = {"Distance": "cm"}
# The topics a person looks at first, in this order; other plotted topics follow by name.
FIRST = ("Distance", "Control", "Control_applied", "cmd_vel", "cmd_vel_applied", "odom", "pose")
POSE_TOPIC = "pose"  # the true pose from /tf (map -> base_link), where the run recorded it
POSE_FIELDS = (("x", "m"), ("y", "m"), ("yaw", "rad"))


@dataclass
class Recorded:
    """One run's plotted numbers: (topic, field) -> times [s] and values, and their units."""

    times: dict[tuple[str, str], list[float]]
    values: dict[tuple[str, str], list[float]]
    units: dict[tuple[str, str], str]

    @property
    def end_s(self) -> float:
        return max((t[-1] for t in self.times.values() if t), default=0.0)


def read_recording(path: Path, true_pose: bool = True) -> Recorded:
    """The plotted fields of every topic in a run's MCAP recording (empty when it has none).
    `true_pose`: read the pose on /tf; a hardware run's /tf holds no measured pose (the bench
    does not know where the robot is: server/hardware/backend.py keeps it at the origin)."""
    recorded = Recorded({}, {}, {})
    if not path.is_file():
        return recorded

    def add(topic: str, name: str, unit: str, time_s: float, value: float) -> None:
        key = (topic, name)
        recorded.times.setdefault(key, []).append(time_s)
        recorded.values.setdefault(key, []).append(float(value))
        recorded.units[key] = unit

    try:
        with open(path, "rb") as f:
            for schema, channel, message in make_reader(f).iter_messages(log_time_order=True):
                type_name = schema.name.replace("/msg/", "/")
                topic = channel.topic.lstrip("/")
                time_s = message.log_time / 1e9  # [s] run time
                if topic == "tf":
                    if not true_pose:
                        continue
                    for x, y, yaw in _base_link_poses(schema.name, message.data):
                        for (name, unit), value in zip(POSE_FIELDS, (x, y, yaw), strict=True):
                            add(POSE_TOPIC, name, unit, time_s, value)
                    continue
                fields = FIELDS.get(type_name)
                if fields is None:
                    continue
                decoded = get_message_class(schema.name).deserialize(message.data)
                for field in fields:
                    unit = TOPIC_UNITS.get(topic, field.unit)
                    add(topic, field.name, unit, time_s, field.read(decoded))
    except McapError:  # a recording cut off by a crash: what was read so far is kept
        pass
    return recorded


def _base_link_poses(type_name: str, data: bytes) -> list[tuple[float, float, float]]:
    poses = []
    for transform in get_message_class(type_name).deserialize(data).transforms:
        if transform.child_frame_id == "base_link":
            q = transform.transform.rotation
            t = transform.transform.translation
            poses.append((t.x, t.y, 2.0 * math.atan2(q.z, q.w)))
    return poses


def time_base(end_s: float) -> np.ndarray:
    """The common sample times [s] from 0 to `end_s`: STEP_S apart, coarser for long runs."""
    step = max(STEP_S, end_s / MAX_POINTS)
    return np.round(np.arange(0.0, end_s + step / 2, step), 6)


def resample(times: list[float], values: list[float], grid: np.ndarray) -> list[float | None]:
    """Zero-order hold of one series on `grid`; None before its first sample, after its last
    (plus HOLD_AFTER_LAST_S), and where a value is not finite (JSON has no NaN)."""
    if not times:
        return [None] * len(grid)
    t = np.asarray(times)
    v = np.asarray(values, dtype=float)
    at = np.searchsorted(t, grid, side="right") - 1
    held = v[np.clip(at, 0, len(v) - 1)]
    valid = (at >= 0) & (grid <= t[-1] + HOLD_AFTER_LAST_S) & np.isfinite(held)
    return [round(float(x), 6) if ok else None for x, ok in zip(held, valid, strict=True)]


def _order(key: tuple[str, str]) -> tuple[int, str, str]:
    topic, name = key
    return (FIRST.index(topic) if topic in FIRST else len(FIRST), topic, name)


def _on(recorded: Recorded, key: tuple[str, str], grid: np.ndarray) -> list[float | None]:
    return resample(recorded.times.get(key, []), recorded.values.get(key, []), grid)


def overlay(simulation: Recorded, hardware: Recorded) -> dict:
    """Both runs' plotted fields on one time base. `shared` says whether both runs have it:
    `Control_applied` is the robot's only (the safety layer), the true pose the simulator's."""
    grid = time_base(max(simulation.end_s, hardware.end_s))
    keys = sorted(set(simulation.times) | set(hardware.times), key=_order)
    series = []
    for key in keys:
        topic, name = key
        series.append(
            {
                "topic": topic,
                "field": name,
                "unit": simulation.units.get(key) or hardware.units.get(key, ""),
                "shared": key in simulation.times and key in hardware.times,
                SIMULATION: _on(simulation, key, grid),
                HARDWARE: _on(hardware, key, grid),
            }
        )
    return {"time_s": [float(t) for t in grid], "series": series}


# ------------------------------------------------------------------------------------ checks
def _number(value: float, unit: str) -> str:
    text = f"{value:.3g}"
    return f"{text} {unit}" if unit else text


def _gap(difference: float, unit: str, comparison: str) -> str:
    """How the robot differs from simulation, said the way a person would."""
    if difference == 0:
        return "the same"
    size = _number(abs(difference), unit)
    if unit == "s":
        return f"{size} {'slower' if difference > 0 else 'faster'}"
    more = "more" if difference > 0 else "less"
    better = (difference < 0) == (comparison == "<=")
    return f"{size} {more} ({'better' if better else 'worse'})"


def check_sentence(name: str, unit: str, comparison: str, sim: float | None,
                   real: float | None) -> str:  # fmt: skip
    label = name.replace("_", " ")
    nothing = "nothing to judge"
    sim_text = _number(sim, unit) if sim is not None else nothing
    real_text = _number(real, unit) if real is not None else nothing
    head = f"{label}: {sim_text} in simulation, {real_text} on the robot"
    if sim is None and real is None:
        return f"{label}: nothing to judge in either run (both ended before it could be measured)"
    if sim is None or real is None:
        return f"{head} (the run ended before the check could be measured)"
    return f"{head}: {_gap(real - sim, unit, comparison)}"


def compare_checks(simulation: list[dict], hardware: list[dict]) -> list[dict]:
    """The exercise's checks of both runs side by side, in the simulation run's order."""
    real_by_name = {c.get("name"): c for c in hardware}
    names = [c.get("name") for c in simulation]
    names += [n for n in real_by_name if n not in names]
    sim_by_name = {c.get("name"): c for c in simulation}
    rows = []
    for name in names:
        sim, real = sim_by_name.get(name, {}), real_by_name.get(name, {})
        unit = sim.get("unit") or real.get("unit") or ""
        comparison = sim.get("comparison") or real.get("comparison") or "<="
        sim_value, real_value = _finite(sim.get("value")), _finite(real.get("value"))
        difference = (
            real_value - sim_value if sim_value is not None and real_value is not None else None
        )
        rows.append(
            {
                "name": name,
                "unit": unit,
                "comparison": comparison,
                "threshold": sim.get("threshold", real.get("threshold")),
                SIMULATION: {"value": sim_value, "passed": sim.get("passed")},
                HARDWARE: {"value": real_value, "passed": real.get("passed")},
                "difference": difference,  # robot - simulation, in `unit`
                "sentence": check_sentence(name, unit, comparison, sim_value, real_value),
            }
        )
    return rows


def _finite(value) -> float | None:
    if isinstance(value, int | float) and math.isfinite(value):
        return float(value)
    return None
