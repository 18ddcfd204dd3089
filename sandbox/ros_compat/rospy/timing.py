"""rospy time: Time, Duration, Rate, sleep, get_time (rospy.timer / rospy.rostime look-alikes).

`Time` and `Duration` are the message-layer classes of sandbox.msgs, so `header.stamp =
rospy.Time.now()` needs no conversion; this module gives `Time` its `now()`.
"""

from __future__ import annotations

from collections.abc import Callable
from numbers import Real
from typing import Any

from sandbox import runtime as _runtime
from sandbox.msgs import Duration, Time
from sandbox.runtime import ROSInterruptException
from sandbox.timers import TimerEvent


def _now(cls: type[Time] | None = None) -> Time:
    node = _runtime.current()
    node.require_init("rospy.Time.now()")
    node.poll()
    return Time.from_nsec(node.clock.now_ns())


# rospy.Time.now() is a static method of the time class itself.
Time.now = staticmethod(_now)  # type: ignore[attr-defined]


def get_rostime() -> Time:
    return _now()


def get_time() -> float:
    """The node's time in seconds: simulated in lockstep runs, wall-clock-paced in realtime."""
    node = _runtime.current()
    node.require_init("rospy.get_time()")
    node.poll()
    return node.clock.now_ns() / 1e9


def duration_ns(duration: Any, what: str) -> int:
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
    node.sleep_until(node.clock.now_ns() + max(0, duration_ns(duration, "rospy.sleep()")))


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
    """Call `callback(event)` every `period` (a rospy.Duration or seconds) of node time, or
    once with `oneshot=True`, as rospy.Timer does; callbacks run while the node sleeps, spins
    or waits (sandbox/timers.py)."""

    def __init__(
        self,
        period: Any,
        callback: Callable[[TimerEvent], Any],
        oneshot: bool = False,
        reset: bool = False,
    ) -> None:
        node = _runtime.current()
        node.require_init("rospy.Timer()")
        if not callable(callback):
            raise TypeError(
                f"rospy.Timer(period, callback): callback must be a function, got {callback!r}"
            )
        period_ns = duration_ns(period, "rospy.Timer()")
        if period_ns <= 0:
            raise ValueError(f"rospy.Timer() needs a positive period, got {period!r}")
        self._period = Duration.from_nsec(period_ns)
        self._callback = callback
        self._oneshot = bool(oneshot)
        self._scheduled = node.timers.add(period_ns, callback, self._oneshot, node.clock.now_ns())

    def shutdown(self) -> None:
        """Stop the timer; a callback already running finishes."""
        self._scheduled.shutdown()

    def is_alive(self) -> bool:
        return not self._scheduled.stopped

    def join(self, timeout: float | None = None) -> None:
        """Wait (in node time) until the timer has stopped, as threading.Thread.join."""
        node = _runtime.current()
        step_ns = self._period.to_nsec()
        deadline = (
            None if timeout is None else node.clock.now_ns() + duration_ns(timeout, "Timer.join()")
        )
        while self.is_alive() and not node.is_shutdown:
            if deadline is not None and node.clock.now_ns() >= deadline:
                return
            target = node.clock.now_ns() + step_ns
            node.sleep_until(target if deadline is None else min(target, deadline))
