"""What checks look at: a run's recording read back (every topic as (time, message) pairs), the
true robot pose from /tf, the run's own metrics and the files its nodes saved.

A ROS 2 run's recording (ros2msg schemas, CDR) reads back as ROS 1 message objects, converted
with sandbox.msgs2.bridge, so a check is written once for both dialects (a stamp is `secs` and
`nsecs` there too). A type with no ROS 1 twin (an action's status) stays a ROS 2 object.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mcap.reader import make_reader

from sandbox.msgs import get_message_class
from server.runs.result import RunResult


@dataclass
class Evidence:
    result: RunResult
    run_dir: Path
    topics: dict[str, list[tuple[float, object]]]
    pose_t: np.ndarray  # [s]
    pose_x: np.ndarray  # [m] true pose from /tf map -> base_link
    pose_y: np.ndarray
    pose_yaw: np.ndarray  # [rad]

    def series(self, topic: str) -> list[tuple[float, object]]:
        return self.topics.get(topic, [])

    def artifacts(self, node: str) -> list[Path]:
        folder = self.run_dir / "artifacts" / node
        return sorted(p for p in folder.rglob("*") if p.is_file()) if folder.is_dir() else []


def load_evidence(result: RunResult, run_dir: Path) -> Evidence:
    topics: dict[str, list[tuple[float, object]]] = {}
    pose_t: list[float] = []
    pose: list[tuple[float, float, float]] = []
    recording = run_dir / "recording.mcap"
    if recording.is_file():
        with open(recording, "rb") as f:
            for schema, channel, message in make_reader(f).iter_messages(log_time_order=True):
                decoded = get_message_class(schema.name).deserialize(message.data)
                if schema.encoding == "ros2msg":
                    decoded = _as_ros1(decoded)
                time_s = message.log_time / 1e9
                topic = channel.topic.lstrip("/")
                if topic == "tf":
                    for transform in decoded.transforms:
                        if transform.child_frame_id == "base_link":
                            q = transform.transform.rotation
                            yaw = 2.0 * np.arctan2(q.z, q.w)
                            t = transform.transform.translation
                            pose_t.append(time_s)
                            pose.append((t.x, t.y, yaw))
                    continue
                topics.setdefault(topic, []).append((time_s, decoded))
    poses = np.array(pose).reshape(-1, 3)
    return Evidence(
        result=result,
        run_dir=run_dir,
        topics=topics,
        pose_t=np.array(pose_t),
        pose_x=poses[:, 0],
        pose_y=poses[:, 1],
        pose_yaw=poses[:, 2],
    )


def _as_ros1(message: object) -> object:
    from sandbox.msgs2.bridge import BridgeError, to_ros1

    try:
        return to_ros1(message)
    except BridgeError:  # no ROS 1 twin: the check sees the ROS 2 message
        return message
