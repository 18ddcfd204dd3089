"""Timers of one node (rospy.Timer): when each falls due and what its callback is told.

rospy runs each Timer on a thread of its own that sleeps until the next expected time and then
calls back with a `TimerEvent` (current_expected, current_real, last_expected, last_real,
last_duration). Here a node has one thread, so the node's waits ask the parent to wake them at
the earliest timer's expected time and fire every timer that is due after the messages of that
wake were delivered (sandbox.runtime.NodeRuntime.wait_until). As in rospy (timer.py), expected
times advance by whole periods from the start, a timer that fell behind skips the missed calls
rather than calling in a burst, and a oneshot timer fires once.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from sandbox.msgs import Time


class TimerEvent:
    """What a timer callback receives (rospy.timer.TimerEvent's fields and meaning)."""

    __slots__ = ("current_expected", "current_real", "last_duration", "last_expected", "last_real")

    def __init__(
        self,
        last_expected: Time | None,
        last_real: Time | None,
        current_expected: Time,
        current_real: Time,
        last_duration: float | None,
    ) -> None:
        self.last_expected = last_expected  # when the previous call should have happened
        self.last_real = last_real  # when it did happen
        self.current_expected = current_expected  # when this call should happen
        self.current_real = current_real  # when this call happens
        self.last_duration = last_duration  # [s] how long the previous callback ran

    def __repr__(self) -> str:
        return (
            f"TimerEvent(current_expected={self.current_expected}, "
            f"current_real={self.current_real}, last_expected={self.last_expected})"
        )


@dataclass(eq=False)
class ScheduledTimer:
    period_ns: int
    callback: Callable[[TimerEvent], Any]
    oneshot: bool
    next_ns: int  # expected time of the next call
    current_ns: int = 0  # expected time of the call being made
    last_expected_ns: int | None = None
    last_real_ns: int | None = None
    last_duration_s: float | None = None
    stopped: bool = False
    schedule: TimerSchedule | None = field(default=None, repr=False)

    def fire(self, now_ns: int) -> None:
        """Call back once (the schedule has already moved `next_ns` on)."""
        expected_ns = self.current_ns
        event = TimerEvent(
            _time(self.last_expected_ns),
            _time(self.last_real_ns),
            Time.from_nsec(expected_ns),
            Time.from_nsec(now_ns),
            self.last_duration_s,
        )
        self.last_expected_ns, self.last_real_ns = expected_ns, now_ns
        self.callback(event)
        # Lockstep time stands still while a callback computes: its duration is 0 there.
        self.last_duration_s = 0.0

    def shutdown(self) -> None:
        self.stopped = True
        if self.schedule is not None:
            self.schedule.remove(self)


def _time(ns: int | None) -> Time | None:
    return None if ns is None else Time.from_nsec(ns)


class TimerSchedule:
    """The node's timers, earliest first."""

    def __init__(self) -> None:
        self._timers: list[ScheduledTimer] = []

    def add(
        self, period_ns: int, callback: Callable[[TimerEvent], Any], oneshot: bool, now_ns: int
    ) -> ScheduledTimer:
        timer = ScheduledTimer(period_ns, callback, oneshot, now_ns + period_ns, schedule=self)
        self._timers.append(timer)
        return timer

    def remove(self, timer: ScheduledTimer) -> None:
        if timer in self._timers:
            self._timers.remove(timer)

    def clear(self) -> None:
        for timer in self._timers:
            timer.stopped = True
        self._timers.clear()

    def next_due_ns(self) -> int | None:
        return min((timer.next_ns for timer in self._timers), default=None)

    def take_due(self, now_ns: int, tolerance_ns: int = 1_000) -> list[ScheduledTimer]:
        """Timers due at `now_ns`, in expected-time order; each is moved to its next period
        (past `now_ns`: missed periods are skipped) or, oneshot, removed."""
        due = sorted(
            (t for t in self._timers if t.next_ns <= now_ns + tolerance_ns),
            key=lambda t: t.next_ns,
        )
        for timer in due:
            timer.current_ns = timer.next_ns
            if timer.oneshot:
                self.remove(timer)
                continue
            timer.next_ns += timer.period_ns
            if timer.next_ns <= now_ns:
                missed = (now_ns - timer.next_ns) // timer.period_ns + 1
                timer.next_ns += missed * timer.period_ns
        return due
