"""What checks look at: a run's recording read back (every topic as (time, message) pairs,
decoded when a check first asks for it), the true robot pose from /tf, the run's own metrics and
the files its nodes saved.

A ROS 2 run's recording (ros2msg schemas, CDR) reads back as ROS 1 message objects, converted
with sandbox.msgs2.bridge, so a check is written once for both dialects (a stamp is `secs` and
`nsecs` there too). A type with no ROS 1 twin (an action's status) stays a ROS 2 object.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mcap.reader import make_reader
from mcap.records import Schema

from sandbox.msgs import get_message_class
from server.runs.result import RunResult


@dataclass
class Evidence:
    result: RunResult
    run_dir: Path
    # Per topic, (time [s], schema, serialized message) in log-time order: a topic is decoded
    # the first time a check asks for it (most checks read two or three of a run's topics).
    recorded: dict[str, list[tuple[float, Schema, bytes]]]
    pose_t: np.ndarray  # [s]
    pose_x: np.ndarray  # [m] true pose from /tf map -> base_link
    pose_y: np.ndarray
    pose_yaw: np.ndarray  # [rad]
    _decoded: dict[str, list[tuple[float, object]]] = field(default_factory=dict, repr=False)

    def series(self, topic: str) -> list[tuple[float, object]]:
        """The topic's messages as (time [s], message), ROS 1 objects for either dialect."""
        if topic not in self._decoded:
            self._decoded[topic] = [
                (time_s, _decode(schema, data))
                for time_s, schema, data in self.recorded.get(topic, [])
            ]
        return self._decoded[topic]

    def artifacts(self, node: str) -> list[Path]:
        folder = self.run_dir / "artifacts" / node
        return sorted(p for p in folder.rglob("*") if p.is_file()) if folder.is_dir() else []


def load_evidence(result: RunResult, run_dir: Path) -> Evidence:
    recorded: dict[str, list[tuple[float, Schema, bytes]]] = {}
    pose_t: list[float] = []
    pose: list[tuple[float, float, float]] = []
    recording = run_dir / "recording.mcap"
    if recording.is_file():
        with open(recording, "rb") as f:
            # In file order, then sorted by log time: the order mcap's log_time_order=True gives
            # (ties in file order, the sort being stable) without its heap of Python objects.
            records = list(make_reader(f).iter_messages(log_time_order=False))
        records.sort(key=_log_time)
        for schema, channel, message in records:
            time_s = message.log_time / 1e9
            topic = channel.topic.lstrip("/")
            if topic != "tf":
                recorded.setdefault(topic, []).append((time_s, schema, message.data))
                continue
            for transform in _decode(schema, message.data).transforms:
                if transform.child_frame_id == "base_link":
                    q = transform.transform.rotation
                    yaw = 2.0 * np.arctan2(q.z, q.w)
                    t = transform.transform.translation
                    pose_t.append(time_s)
                    pose.append((t.x, t.y, yaw))
    poses = np.array(pose).reshape(-1, 3)
    return Evidence(
        result=result,
        run_dir=run_dir,
        recorded=recorded,
        pose_t=np.array(pose_t),
        pose_x=poses[:, 0],
        pose_y=poses[:, 1],
        pose_yaw=poses[:, 2],
    )


def _decode(schema: Schema, data: bytes) -> object:
    decoded = get_message_class(schema.name).deserialize(data)
    return _as_ros1(decoded) if schema.encoding == "ros2msg" else decoded


def _log_time(record: tuple) -> int:
    return record[2].log_time


def _as_ros1(message: object) -> object:
    from sandbox.msgs2.bridge import BridgeError, to_ros1

    try:
        return to_ros1(message)
    except BridgeError:  # no ROS 1 twin: the check sees the ROS 2 message
        return message
