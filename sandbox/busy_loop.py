"""How a node that never sleeps lets time pass: the busy-loop model.

In rospy a loop such as `while not rospy.is_shutdown(): pub.publish(cmd)` runs beside callback
threads, and the clock (wall or /clock) moves on whatever the loop does. A RoboDojo node has one
thread and, in lockstep, a clock that stands still while it computes. So the calls such a loop
spins on (is_shutdown(), Time.now(), get_time(), publish() and the `time` module's clocks) are
counted: past `FREE_POLLS` of them since the node's last wake, each costs `POLL_COST_NS` of
simulated time, and every `BUSY_SLICE_NS` of it the node yields as if it had slept (its
messages leave, callbacks and timers run). In realtime the wall clock moves by itself, and the
node yields every `REALTIME_BUSY_SLICE_S`. Counting calls, not measuring them, keeps lockstep
runs reproducible: same code, same seed, same run. A rate loop makes a few polls per period and
never pays.
"""

from __future__ import annotations

from sandbox.protocol import Clock
from sandbox.vclock import NodeClock, wall_monotonic_ns

FREE_POLLS = 100  # [calls] polls between two wakes that cost no time
POLL_COST_NS = 20_000  # [ns] what one poll past the free ones costs: a rospy publish() or
# is_shutdown() round on a laptop takes 10-50 us
# [ns] lockstep: a busy node yields after this much polled time. CPython hands the GIL from a
# spinning thread to a waiting one every sys.getswitchinterval() = 5 ms by default, so in real
# rospy a busy main loop lets its callback threads run about this often.
BUSY_SLICE_NS = 5_000_000
REALTIME_BUSY_SLICE_S = 0.01  # [s] realtime: a busy node yields after this much wall time


def wall_s() -> float:
    """The real monotonic clock [s] (the `time` module's is the node's clock in lockstep)."""
    return wall_monotonic_ns() / 1e9


class BusyLoopModel:
    def __init__(self, clock: NodeClock) -> None:
        self._clock = clock
        self._polls = 0
        self._woken_ns = clock.now_ns()
        self._woken_wall_s = wall_s()

    def woke(self) -> None:
        """The node was woken: its polls start afresh."""
        self._polls, self._woken_ns, self._woken_wall_s = 0, self._clock.now_ns(), wall_s()

    def count(self) -> bool:
        """Count one poll (charging its cost in lockstep); True when the node should yield."""
        self._polls += 1
        if self._polls <= FREE_POLLS:
            return False
        if self._clock.mode is Clock.LOCKSTEP:
            self._clock.advance_ns(POLL_COST_NS)
            return self._clock.now_ns() - self._woken_ns >= BUSY_SLICE_NS
        return wall_s() - self._woken_wall_s >= REALTIME_BUSY_SLICE_S
