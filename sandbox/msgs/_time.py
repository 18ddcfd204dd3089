"""ROS1 ``time`` and ``duration`` primitives as small value classes.

Both store whole seconds plus nanoseconds, canonicalised so that ``0 <= nsecs < 1e9`` (a negative
duration keeps its sign in ``secs``, as genpy does). ``Header.stamp`` is a :class:`Time`; the rospy
compatibility layer aliases ``rospy.Time`` and ``rospy.Duration`` to these classes.
"""

from __future__ import annotations

from typing import Any, Self

from sandbox.units import NS_PER_S


class _TimeValue:
    """Shared storage, conversions and ordering of Time and Duration."""

    __slots__ = ("nsecs", "secs")
    secs: int
    nsecs: int

    def __init__(self, secs: float = 0, nsecs: int = 0) -> None:
        if isinstance(secs, float):
            # rospy accepts Time(1.5): float seconds, with nsecs left at 0.
            if nsecs:
                raise ValueError(f"{type(self).__name__}: give float seconds or nsecs, not both")
            total = round(secs * NS_PER_S)
        else:
            total = int(secs) * NS_PER_S + int(nsecs)
        secs_part, nsecs_part = divmod(total, NS_PER_S)
        # Mutable attributes, like rospy's, so `msg.header.stamp.secs = 5` keeps working.
        self.secs = secs_part
        self.nsecs = nsecs_part

    @classmethod
    def from_sec(cls, seconds: float) -> Self:
        """Build from floating-point seconds (rounded to the nearest nanosecond)."""
        return cls(0, round(seconds * NS_PER_S))

    @classmethod
    def from_nsec(cls, nanoseconds: int) -> Self:
        """Build from integer nanoseconds."""
        return cls(0, nanoseconds)

    def to_sec(self) -> float:
        """Seconds as a float (loses precision below ~100 ns for current epoch times)."""
        return self.secs + self.nsecs / NS_PER_S

    def to_nsec(self) -> int:
        """Exact integer nanoseconds."""
        return self.secs * NS_PER_S + self.nsecs

    def is_zero(self) -> bool:
        return self.secs == 0 and self.nsecs == 0

    def __bool__(self) -> bool:
        return not self.is_zero()

    def __repr__(self) -> str:
        return f"{type(self).__name__}(secs={self.secs}, nsecs={self.nsecs})"

    def __hash__(self) -> int:
        return hash((type(self).__name__, self.secs, self.nsecs))

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return self.secs == other.secs and self.nsecs == other.nsecs  # type: ignore[attr-defined]

    def _ordered(self, other: object) -> int | None:
        if type(other) is not type(self):
            return None
        return self.to_nsec() - other.to_nsec()  # type: ignore[attr-defined]

    def __lt__(self, other: object) -> bool:
        diff = self._ordered(other)
        return NotImplemented if diff is None else diff < 0

    def __le__(self, other: object) -> bool:
        diff = self._ordered(other)
        return NotImplemented if diff is None else diff <= 0

    def __gt__(self, other: object) -> bool:
        diff = self._ordered(other)
        return NotImplemented if diff is None else diff > 0

    def __ge__(self, other: object) -> bool:
        diff = self._ordered(other)
        return NotImplemented if diff is None else diff >= 0


class Duration(_TimeValue):
    """A signed time span (ROS1 ``duration``: int32 secs, int32 nsecs on the wire)."""

    __slots__ = ()

    def __neg__(self) -> Duration:
        return Duration.from_nsec(-self.to_nsec())

    def __abs__(self) -> Duration:
        return Duration.from_nsec(abs(self.to_nsec()))

    def __add__(self, other: object) -> Any:
        if isinstance(other, Duration):
            return Duration.from_nsec(self.to_nsec() + other.to_nsec())
        if isinstance(other, Time):
            return Time.from_nsec(self.to_nsec() + other.to_nsec())
        return NotImplemented

    def __sub__(self, other: object) -> Duration:
        if isinstance(other, Duration):
            return Duration.from_nsec(self.to_nsec() - other.to_nsec())
        return NotImplemented

    def __mul__(self, factor: float) -> Duration:
        if isinstance(factor, int | float) and not isinstance(factor, bool):
            return Duration.from_nsec(round(self.to_nsec() * factor))
        return NotImplemented

    __rmul__ = __mul__

    def __truediv__(self, divisor: object) -> Any:
        if isinstance(divisor, Duration):
            return self.to_nsec() / divisor.to_nsec()
        if isinstance(divisor, int | float) and not isinstance(divisor, bool):
            return Duration.from_nsec(round(self.to_nsec() / divisor))
        return NotImplemented


class Time(_TimeValue):
    """A point in time (ROS1 ``time``: uint32 secs, uint32 nsecs since the epoch or sim start)."""

    __slots__ = ()

    def __init__(self, secs: float = 0, nsecs: int = 0) -> None:
        super().__init__(secs, nsecs)
        if self.secs < 0:
            raise ValueError(f"Time cannot be negative (got {self.to_sec()} s); use a Duration")

    def __add__(self, other: object) -> Time:
        if isinstance(other, Duration):
            return Time.from_nsec(self.to_nsec() + other.to_nsec())
        return NotImplemented

    __radd__ = __add__

    def __sub__(self, other: object) -> Any:
        if isinstance(other, Time):
            return Duration.from_nsec(self.to_nsec() - other.to_nsec())
        if isinstance(other, Duration):
            return Time.from_nsec(self.to_nsec() - other.to_nsec())
        return NotImplemented
