"""rospy time: Time, Duration, Rate, sleep, get_time (rospy.timer / rospy.rostime look-alikes).

`Time` and `Duration` are the message-layer classes of sandbox.msgs, so `header.stamp =
rospy.Time.now()` needs no conversion; this module gives `Time` its `now()`.
"""

from __future__ import annotations

from numbers import Real
from typing import Any

from sandbox import runtime as _runtime
from sandbox.msgs import Duration, Time
from sandbox.runtime import ROSInterruptException


def _now(cls: type[Time] | None = None) -> Time:
    node = _runtime.current()
    node.require_init("rospy.Time.now()")
    return Time.from_nsec(node.clock.now_ns())


# rospy.Time.now() is a static method of the time class itself.
Time.now = staticmethod(_now)  # type: ignore[attr-defined]


def get_rostime() -> Time:
    return _now()


def get_time() -> float:
    """The node's time in seconds: simulated in lockstep runs, wall-clock-paced in realtime."""
    node = _runtime.current()
    node.require_init("rospy.get_time()")
    return node.clock.now_ns() / 1e9


def _duration_ns(duration: Any, what: str) -> int:
    if isinstance(duration, Duration):
        return duration.to_nsec()
    if isinstance(duration, Real) and not isinstance(duration, bool):
        return round(float(duration) * 1e9)
    raise TypeError(f"{what} takes seconds (a number) or a rospy.Duration, got {duration!r}")


def sleep(duration: Any) -> None:
    """Sleep for `duration` seconds of node time; callbacks run meanwhile."""
    node = _runtime.current()
    node.require_init("rospy.sleep()")
    if node.is_shutdown:
        raise ROSInterruptException("ROS shutdown request")
    node.sleep_until(node.clock.now_ns() + max(0, _duration_ns(duration, "rospy.sleep()")))


class Rate:
    """Sleep so a loop runs at `hz`: each deadline is the previous one plus one period; a loop
    that has fallen more than a period behind does not wait and starts afresh from now (as
    rospy.Rate does)."""

    def __init__(self, hz: float, reset: bool = False) -> None:
        node = _runtime.current()
        node.require_init("rospy.Rate()")
        if not isinstance(hz, Real) or isinstance(hz, bool) or not 0 < hz < float("inf"):
            raise ValueError(f"rospy.Rate() needs a positive rate in Hz, got {hz!r}")
        self._node = node
        self.sleep_dur = Duration.from_nsec(round(1e9 / float(hz)))
        self._period_ns = self.sleep_dur.to_nsec()
        self.last_time = Time.from_nsec(node.clock.now_ns())

    def _last_ns(self, now_ns: int) -> int:
        last = self.last_time.to_nsec()
        return min(last, now_ns)  # time moved backwards: start again from now

    def remaining(self) -> Duration:
        now = self._node.clock.now_ns()
        return Duration.from_nsec(self._last_ns(now) + self._period_ns - now)

    def sleep(self) -> None:
        node = self._node
        if node.is_shutdown:
            raise ROSInterruptException("ROS shutdown request")
        now = node.clock.now_ns()
        deadline = self._last_ns(now) + self._period_ns
        if now - deadline > self._period_ns:
            deadline = now  # more than a period late: do not wait, restart the schedule
        node.sleep_until(max(deadline, now))
        self.last_time = Time.from_nsec(deadline)


class Timer:
    """Not available: a timer would need a thread; use a Rate loop or the step API."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        raise _runtime.ROSException(
            "rospy.Timer is not supported in RoboDojo nodes; use `rate = rospy.Rate(hz)` and "
            "call your function in a `while not rospy.is_shutdown():` loop"
        )
