"""A finished run's recording read back for replay: the state of the view at any time.

`{run_dir}/recording.mcap` (server/runs/recorder.py) holds every topic; /tf carries map ->
base_link at 30 Hz. Loading keeps each topic's messages as raw bytes with their times (a
ten-minute TurtleBot run is ~20 MB, decoded it would be several times that) and the poses as
arrays; `state_at(t)` decodes only the newest message of each topic at or before `t`, with the
decoder the live telemetry uses (`server.service.decode.decode`), and folds them into a
`ViewState` exactly as a live view would have. The trail comes from every pose up to `t`.
"""

from __future__ import annotations

import bisect
import functools
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mcap.reader import make_reader

from server.service.decode import decode
from server.sim.world import LightSource
from server.viz.view_state import TRAIL_STEP_M, ViewState

DECODED_KEPT = 512  # decoded messages cached: scrubbing back and forth decodes each once


class RecordingError(ValueError):
    """The recording cannot be read; the message says what is wrong."""


@dataclass
class TopicSeries:
    type_name: str
    times_s: list[float] = field(default_factory=list)
    data: list[bytes] = field(default_factory=list)


@dataclass
class Recording:
    path: Path
    metadata: dict[str, str]
    topics: dict[str, TopicSeries]
    trail_times_s: np.ndarray  # [s] a trail point every TRAIL_STEP_M [m] of the true path
    trail_xy: np.ndarray  # (N, 2) [m]
    duration_s: float

    def __post_init__(self) -> None:
        self._decoded = functools.lru_cache(maxsize=DECODED_KEPT)(self._decode)

    def _decode(self, topic: str, index: int) -> dict:
        series = self.topics[topic]
        return decode(series.type_name, series.data[index])

    def state_at(self, time_s: float, lights: tuple[LightSource, ...] = ()) -> ViewState:
        """The view at run time `time_s` [s]: each topic's newest message at or before it."""
        state = ViewState(lights=lights)
        for topic, series in self.topics.items():
            index = bisect.bisect_right(series.times_s, time_s) - 1
            if index < 0:
                continue
            try:
                message = self._decoded(topic, index)
            except Exception:  # a message this build cannot decode is left out
                continue
            state.apply(topic, series.type_name, series.times_s[index], message)
        shown = int(np.searchsorted(self.trail_times_s, time_s, side="right"))
        state.trail.clear()
        state.trail.extend(map(tuple, self.trail_xy[:shown].tolist()))
        state.time_s = time_s
        return state


def _base_pose(tf: dict) -> tuple[float, float] | None:
    for stamped in tf["transforms"]:
        if stamped["header"]["frame_id"] == "map" and stamped["child_frame_id"] == "base_link":
            t = stamped["transform"]["translation"]
            return t["x"], t["y"]
    return None


def load_recording(path: str | Path) -> Recording:
    """Read `path` (an MCAP file a run wrote); RecordingError if it is missing or unreadable."""
    path = Path(path)
    if not path.is_file():
        raise RecordingError(f"no recording at {path}: the run left none (it failed to start?)")
    topics: dict[str, TopicSeries] = {}
    metadata: dict[str, str] = {}
    trail_t: list[float] = []
    trail_xy: list[tuple[float, float]] = []
    end_s = 0.0
    try:
        with open(path, "rb") as handle:
            reader = make_reader(handle)
            for record in reader.iter_metadata():
                if record.name == "run":
                    metadata = dict(record.metadata)
            handle.seek(0)
            reader = make_reader(handle)
            for schema, channel, message in reader.iter_messages(log_time_order=True):
                topic = channel.topic.lstrip("/")
                time_s = message.log_time / 1e9
                series = topics.setdefault(topic, TopicSeries(schema.name))
                series.times_s.append(time_s)
                series.data.append(message.data)
                end_s = max(end_s, time_s)
                if topic == "tf":
                    xy = _base_pose(decode(schema.name, message.data))
                    if xy is not None and (
                        not trail_xy
                        or math.hypot(xy[0] - trail_xy[-1][0], xy[1] - trail_xy[-1][1])
                        >= TRAIL_STEP_M
                    ):
                        trail_t.append(time_s)
                        trail_xy.append(xy)
    except RecordingError:
        raise
    except Exception as error:  # a truncated or foreign file
        raise RecordingError(f"cannot read the recording {path.name}: {error}") from None
    return Recording(
        path=path,
        metadata=metadata,
        topics=topics,
        trail_times_s=np.array(trail_t, dtype=np.float64),
        trail_xy=np.array(trail_xy, dtype=np.float64).reshape(-1, 2),
        duration_s=end_s,
    )
