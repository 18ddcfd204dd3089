"""The node's clock, and the `time` module patched to follow it in lockstep runs.

A node's clock reads the run's time in seconds: it starts at `NodeInfo.start_time_s` and each
`Wake(time_s)` sets it. The two clock modes:

- LOCKSTEP (virtual time, as ROS with use_sim_time): the clock stands still while the node
  computes and jumps to `time_s` at each wake. `time.time()`, `time.monotonic()`,
  `time.perf_counter()` (and their `_ns` forms) all return this simulated time, and
  `time.sleep(d)` sleeps in simulated time (a Yield, like rospy.sleep(d)). So a script that
  measures its own loop period sees exactly the simulated period. time.time() is the run time,
  not an epoch: a lockstep run starts near 0.
- REALTIME: the `time` module is left alone. The node's clock is the last wake's `time_s` plus
  the wall time elapsed since that wake, so rospy time stays aligned with the parent's run clock.

Time is kept in integer nanoseconds so that periods add up without floating-point drift.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from numbers import Real

from sandbox.protocol import Clock

wall_monotonic_ns = time.monotonic_ns
_PATCHED = (
    "time",
    "time_ns",
    "monotonic",
    "monotonic_ns",
    "perf_counter",
    "perf_counter_ns",
    "sleep",
)


def seconds_to_ns(seconds: float) -> int:
    return round(seconds * 1e9)


class NodeClock:
    """Now, for one node, in [ns] of run time."""

    def __init__(self, mode: Clock, start_time_s: float) -> None:
        self.mode = mode
        self._anchor_ns = seconds_to_ns(start_time_s)  # run time at the last wake
        self._anchor_wall_ns = wall_monotonic_ns()
        self._last_ns = self._anchor_ns  # never hand out a time earlier than one already given
        # Realtime: the run's clock starts once every node has loaded, so a node's clock stands
        # at the start time until its first wake (else it would lead the run's by its load).
        self._running = False

    def now_ns(self) -> int:
        now = self._anchor_ns
        if self.mode is Clock.REALTIME and self._running:
            now += wall_monotonic_ns() - self._anchor_wall_ns
        if now < self._last_ns:
            now = self._last_ns
        self._last_ns = now
        return now

    def now_s(self) -> float:
        return self.now_ns() / 1e9

    def advance_ns(self, duration_ns: int) -> None:
        """Lockstep: let the node's own clock run on by `duration_ns` while it computes (the
        busy-loop model of sandbox.runtime); the next wake is no earlier than that."""
        self._anchor_ns = self.now_ns() + duration_ns

    def wake(self, time_s: float) -> None:
        if self.mode is Clock.REALTIME:
            # The parent's clock is the truth: keeping our own reading when it is ahead would
            # let every late wake add to a lead that never goes away. now_ns() still never
            # goes backwards (it holds until the run's time catches up).
            self._anchor_ns = seconds_to_ns(time_s)
            self._running = True
        else:  # lockstep: a busy node's own clock may have run past the wake (advance_ns)
            self._anchor_ns = max(seconds_to_ns(time_s), self.now_ns())
        self._anchor_wall_ns = wall_monotonic_ns()


class TimePatch:
    """Replaces the `time` module's clocks and sleep with the node's; `remove()` undoes it.

    Process-wide while installed: the child runs one node, so every thread sees node time.
    """

    def __init__(
        self,
        clock: NodeClock,
        sleep: Callable[[float], None],
        poll: Callable[[], None] = lambda: None,
        clocks: bool = True,
    ) -> None:
        """`clocks` False (a realtime run): only time.sleep() is the node's (so callbacks run
        while a script sleeps with it, as rospy's threads would run them); the clock functions
        stay the wall clock."""
        self._saved = {name: getattr(time, name) for name in _PATCHED}
        real_sleep = self._saved["sleep"]
        main_thread = threading.get_ident()

        # `poll`: a loop that spins on time.time() lets simulated time pass (sandbox.runtime).
        def time_s() -> float:
            poll()
            return clock.now_ns() / 1e9

        def time_ns() -> int:
            poll()
            return clock.now_ns()

        def sleep_s(seconds: float) -> None:
            if not isinstance(seconds, Real) or isinstance(seconds, bool):
                raise TypeError(
                    f"time.sleep() takes a number of seconds, got {type(seconds).__name__}"
                )
            if seconds < 0:
                raise ValueError("sleep length must be non-negative")
            if threading.get_ident() != main_thread:
                real_sleep(seconds)  # a student's own thread: only the node's may yield
                return
            sleep(float(seconds))

        replacements = {
            "time": time_s,
            "time_ns": time_ns,
            "monotonic": time_s,
            "monotonic_ns": time_ns,
            "perf_counter": time_s,
            "perf_counter_ns": time_ns,
            "sleep": sleep_s,
        }
        if not clocks:
            replacements = {"sleep": sleep_s}
        for name, function in replacements.items():
            function.__name__ = name
            function.__qualname__ = name
            setattr(time, name, function)

    def remove(self) -> None:
        for name, function in self._saved.items():
            setattr(time, name, function)
