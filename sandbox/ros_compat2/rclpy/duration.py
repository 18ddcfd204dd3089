"""rclpy.duration.Duration: a signed span of time in integer nanoseconds.

Arithmetic and comparison as rclpy/duration.py: + and - with another Duration, * with an int or
a float (inf gives Infinite, nan raises ValueError), comparisons only with Durations (anything
else is NotImplemented, so Python raises TypeError), OverflowError past int64.
"""

from __future__ import annotations

import math
from typing import Any

from .constants import S_TO_NS

_INT64_MAX = 2**63 - 1
RMW_DURATION_INFINITE = _INT64_MAX  # [ns] rmw's "infinite" duration


class Duration:
    """A period between two time points, with nanosecond precision."""

    __slots__ = ("_nanoseconds",)

    def __init__(self, *, seconds: float = 0, nanoseconds: int = 0) -> None:
        total = int(seconds * S_TO_NS) + int(nanoseconds)
        if total >= 2**63 or total < -(2**63):
            raise OverflowError("Total nanoseconds value is too large to store in C duration.")
        self._nanoseconds = total

    @property
    def nanoseconds(self) -> int:
        return self._nanoseconds

    def __repr__(self) -> str:
        return f"Duration(nanoseconds={self._nanoseconds})"

    def __str__(self) -> str:
        if self._nanoseconds == RMW_DURATION_INFINITE:
            return "Infinite"
        return f"{self._nanoseconds} nanoseconds"

    __hash__ = None  # type: ignore[assignment]  # unhashable, as rclpy's (it defines __eq__)

    def __add__(self, other: Any) -> Duration:
        if isinstance(other, Duration):
            return Duration(nanoseconds=self._nanoseconds + other._nanoseconds)
        return NotImplemented

    def __sub__(self, other: Any) -> Duration:
        if isinstance(other, Duration):
            return Duration(nanoseconds=self._nanoseconds - other._nanoseconds)
        return NotImplemented

    def __mul__(self, other: Any) -> Duration:
        if isinstance(other, bool):
            return NotImplemented
        if isinstance(other, int):
            return Duration(nanoseconds=self._nanoseconds * other)
        if isinstance(other, float):
            if not math.isfinite(other):
                if other == float("inf"):
                    return Infinite
                raise ValueError("Can't multiply duration with nan")
            return Duration(nanoseconds=int(self._nanoseconds * other))
        return NotImplemented

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Duration):
            return self._nanoseconds == other._nanoseconds
        return NotImplemented

    def __ne__(self, other: object) -> bool:
        if isinstance(other, Duration):
            return self._nanoseconds != other._nanoseconds
        return NotImplemented

    def __lt__(self, other: object) -> bool:
        if isinstance(other, Duration):
            return self._nanoseconds < other._nanoseconds
        return NotImplemented

    def __le__(self, other: object) -> bool:
        if isinstance(other, Duration):
            return self._nanoseconds <= other._nanoseconds
        return NotImplemented

    def __gt__(self, other: object) -> bool:
        if isinstance(other, Duration):
            return self._nanoseconds > other._nanoseconds
        return NotImplemented

    def __ge__(self, other: object) -> bool:
        if isinstance(other, Duration):
            return self._nanoseconds >= other._nanoseconds
        return NotImplemented

    def to_msg(self) -> Any:
        """As a builtin_interfaces/msg/Duration (sec may be negative, nanosec in [0, 1e9))."""
        from builtin_interfaces.msg import Duration as DurationMsg

        seconds, nanoseconds = divmod(self._nanoseconds, S_TO_NS)
        return DurationMsg(sec=seconds, nanosec=nanoseconds)

    @classmethod
    def from_msg(cls, msg: Any) -> Duration:
        from builtin_interfaces.msg import Duration as DurationMsg

        if not isinstance(msg, DurationMsg):
            raise TypeError("Must pass a builtin_interfaces.msg.Duration object")
        return cls(seconds=msg.sec, nanoseconds=msg.nanosec)

    def get_c_duration(self) -> Duration:
        return self


Infinite = Duration(nanoseconds=RMW_DURATION_INFINITE)
