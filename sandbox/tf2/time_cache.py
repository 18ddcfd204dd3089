"""One frame's history in a tf2 buffer: its transforms to its parent over the last
`cache_time`, or a single timeless one for a static frame.

Behaviour as tf2's TimeCache and StaticCache (ros/geometry2, tf2/src/cache.cpp and
static_cache.cpp): a lookup at time 0 takes the latest; between two stamps the translation is
interpolated linearly and the rotation by slerp (when both have the same parent, else the
older one is used); outside the stored stamps the lookup fails with tf2's sentences
("Lookup would require extrapolation ..."); data older than `cache_time` behind the newest is
refused (TF_OLD_DATA), a stamp already stored is refused (TF_REPEATED_DATA), and the oldest
entries are dropped once they are more than `cache_time` behind the newest.
Times are integer nanoseconds.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass

from sandbox.units import NS_PER_S

from . import _math


@dataclass(frozen=True)
class Stored:
    """A transform as stored: the child frame's pose in `parent` at `stamp_ns`."""

    stamp_ns: int
    parent: str
    pose: _math.Pose


def _seconds(ns: int) -> str:
    return f"{ns / NS_PER_S:.9f}"


class TimeCache:
    """The transforms of one frame over time, oldest first."""

    def __init__(self, max_storage_ns: int) -> None:
        self.max_storage_ns = max_storage_ns
        self._stamps: list[int] = []
        self._data: list[Stored] = []

    def insert(self, data: Stored) -> str | None:
        """Store `data`; the reason (tf2's words) when it is refused."""
        if self._stamps and self._stamps[-1] > data.stamp_ns + self.max_storage_ns:
            return (
                "TF_OLD_DATA ignoring data from the past (Possible reasons are listed at "
                "http://wiki.ros.org/tf/Errors%20explained)"
            )
        index = bisect.bisect_left(self._stamps, data.stamp_ns)
        if index < len(self._stamps) and self._stamps[index] == data.stamp_ns:
            return "TF_REPEATED_DATA ignoring data with redundant timestamp"
        self._stamps.insert(index, data.stamp_ns)
        self._data.insert(index, data)
        newest = self._stamps[-1]
        drop = 0
        while self._stamps[drop] + self.max_storage_ns < newest:
            drop += 1
        if drop:
            del self._stamps[:drop], self._data[:drop]
        return None

    def get(self, time_ns: int) -> tuple[Stored | None, str]:
        """The frame's transform at `time_ns` (0: the latest), or None and why not."""
        if not self._data:
            return None, ""
        if time_ns == 0:
            return self._data[-1], ""
        earliest, latest = self._stamps[0], self._stamps[-1]
        if len(self._data) == 1:
            if time_ns == latest:
                return self._data[0], ""
            return None, (
                f"Lookup would require extrapolation at time {_seconds(time_ns)}, but only "
                f"time {_seconds(latest)} is in the buffer"
            )
        if time_ns > latest:
            return None, (
                f"Lookup would require extrapolation {_seconds(time_ns - latest)}s into the "
                f"future.  Requested time {_seconds(time_ns)} but the latest data is at time "
                f"{_seconds(latest)}"
            )
        if time_ns < earliest:
            return None, (
                f"Lookup would require extrapolation {_seconds(earliest - time_ns)}s into the "
                f"past.  Requested time {_seconds(time_ns)} but the earliest data is at time "
                f"{_seconds(earliest)}"
            )
        after = bisect.bisect_left(self._stamps, time_ns)
        newer = self._data[after]
        if newer.stamp_ns == time_ns:
            return newer, ""
        older = self._data[after - 1]
        if older.parent != newer.parent:
            return older, ""
        ratio = (time_ns - older.stamp_ns) / (newer.stamp_ns - older.stamp_ns)
        (t0, r0), (t1, r1) = older.pose, newer.pose
        pose = (_math.lerp(t0, t1, ratio), _math.slerp(r0, r1, ratio))
        return Stored(time_ns, older.parent, pose), ""

    def latest(self) -> tuple[int, str | None]:
        """(newest stamp, its parent); (0, None) when empty."""
        if not self._data:
            return 0, None
        return self._stamps[-1], self._data[-1].parent

    def span(self) -> tuple[int, int, int]:
        """(number of entries, oldest stamp, newest stamp)."""
        if not self._data:
            return 0, 0, 0
        return len(self._data), self._stamps[0], self._stamps[-1]

    def clear(self) -> None:
        self._stamps.clear()
        self._data.clear()


class StaticCache:
    """A static frame: one transform, valid at every time (its stamp counts as 0)."""

    def __init__(self) -> None:
        self._data: Stored | None = None

    def insert(self, data: Stored) -> str | None:
        self._data = data
        return None

    def get(self, time_ns: int) -> tuple[Stored | None, str]:
        if self._data is None:
            return None, ""
        return Stored(time_ns, self._data.parent, self._data.pose), ""

    def latest(self) -> tuple[int, str | None]:
        return 0, None if self._data is None else self._data.parent

    def span(self) -> tuple[int, int, int]:
        return 1, 0, 0

    def clear(self) -> None:
        """tf2 keeps static transforms when the buffer is cleared."""
