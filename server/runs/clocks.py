"""The two clocks a run can keep.

*Lockstep* (virtual time, as fast as the machine allows, deterministic): every node sleeps until
a wake time it chose (or, spinning, until a message arrives for it); the simulation advances
from one wake-up to the next, never further than the next sensor message a spinning node may
be waiting for. Nodes due at the same instant wake one after another in launch-file order, and
what one publishes reaches the others at their next wake. Same seed, same code: the same
recorded messages, byte for byte.

*Realtime* (wall clock, real-time factor 1): the simulation keeps advancing while nodes compute,
so a slow controller shows up as latency, as on a real robot. Nodes are woken without waiting
(`begin_wake`) and their replies collected as they come, so one slow node does not hold up the
others; a command takes effect at the moment its reply arrives. Every realtime run of the
process is driven by one scheduler thread (earliest deadline first), not a thread each.

Both see a run only through `ClockedRun` (what is due, when the next event is, advance to) and
share its one test of "is this node due" and "what happens next" (server/runs/core.py).
"""

from __future__ import annotations

import contextlib
import os
import select
import sys
import threading
import time
from typing import TYPE_CHECKING, Protocol

from sandbox.units import NS_PER_S

if TYPE_CHECKING:
    from server.runs.slots import NodeSlot

# Two spinning nodes can answer each other forever without time passing; after this many
# wake rounds at one instant, time moves on to the next event.
MAX_ROUNDS_PER_INSTANT = 100
# [s] longest the realtime loop sleeps when nothing is due; commands and node replies wake it
# earlier through their fds, so this only bounds how stale `progress` can look.
REALTIME_IDLE_S = 0.05
GIL_SWITCH_INTERVAL_S = 0.0005  # [s] see run_realtime
REALTIME_REPLY_ROUNDS = 4  # rounds of collecting replies and waking nodes in one realtime step
PAUSED_POLL_S = 0.1  # [s] a paused lockstep loop waits this long for a command at a time


class ClockedRun(Protocol):
    """What a clock sees of a run (server/runs/core.py's RunCore): when things are due, and
    the means to move time on and wake nodes. A clock never reaches further into the run."""

    time_ns: int  # run time reached [ns]
    duration_ns: int  # [ns] the run covers [0, duration)

    @property
    def tick_s(self) -> float: ...  # [s] the robot's smallest step

    @property
    def paused(self) -> bool: ...

    @property
    def command_fd(self) -> int: ...  # readable while a command waits

    def apply_commands(self) -> None: ...

    def wait_for_command(self, timeout_s: float) -> None: ...

    def due_nodes(self, now_ns: int) -> list[NodeSlot]: ...

    def next_event_ns(self, *, every_publication: bool) -> int: ...

    def advance_to(self, time_ns: int) -> None: ...

    def wake(self, slot: NodeSlot, now_ns: int) -> None: ...  # and wait for its reply

    def begin_wake(self, slot: NodeSlot, now_ns: int) -> None: ...  # without waiting

    def collect_replies(self) -> bool: ...

    def reply_fds(self) -> list[int]: ...


def run_lockstep(run: ClockedRun) -> None:
    rounds = 0
    tick_ns = round(run.tick_s * NS_PER_S)
    while True:
        run.apply_commands()
        while run.paused:
            run.wait_for_command(PAUSED_POLL_S)
        now = run.time_ns
        if now >= run.duration_ns:
            return  # the run covers [0, duration): nothing wakes at its last instant
        due = run.due_nodes(now)
        if due and rounds < MAX_ROUNDS_PER_INSTANT:
            rounds += 1
            for slot in due:
                run.wake(slot, now)
            continue
        rounds = 0
        # The robot's publications are events only while a node may wake on one: a longer
        # step publishes the same messages. Always move on by at least one tick.
        next_ns = run.next_event_ns(every_publication=False)
        run.advance_to(max(next_ns, now + tick_ns))


class RealtimeDriver:
    """One realtime run, advanced in non-blocking steps by the shared scheduler."""

    def __init__(self, run: ClockedRun) -> None:
        self.run = run
        self.start = time.monotonic()
        self.deadline = self.start  # monotonic time of the next thing to do
        self.fds: list[int] = [run.command_fd]
        self.finished = threading.Event()
        self.error: BaseException | None = None

    def step(self) -> bool:
        """Do what is due now; False once the run's duration is reached."""
        run = self.run
        run.apply_commands()
        now_ns = round((time.monotonic() - self.start) * NS_PER_S)
        run.advance_to(min(now_ns, run.duration_ns))
        if run.time_ns >= run.duration_ns:
            return False
        # A reply may carry a message another node waits on (a service request, its answer):
        # go round again while replies come in, so such a node is woken now, not at the next
        # deadline (a few rounds at most: a busy node replies at once, every time).
        replied, rounds = True, 0
        while replied and rounds < REALTIME_REPLY_ROUNDS:
            rounds += 1
            replied = run.collect_replies()
            for slot in run.due_nodes(run.time_ns):
                run.begin_wake(slot, run.time_ns)
        # Next: a sleeping node's wake time, the robot's next message, or an idle check; a
        # node still computing is not due (its reply makes its fds readable).
        next_ns = run.next_event_ns(every_publication=True)
        self.deadline = min(self.start + next_ns / NS_PER_S, time.monotonic() + REALTIME_IDLE_S)
        self.fds = [run.command_fd, *run.reply_fds()]
        return True


class RealtimeScheduler:
    """One thread that drives every realtime run of the process, earliest deadline first.

    Twenty run threads contending for the GIL made wake-ups tens of milliseconds late; one
    thread that sleeps in select() until the earliest deadline or the first node reply keeps
    them on time and spends less CPU. A run that raises ends alone; the others go on.
    """

    def __init__(self) -> None:
        self._drivers: list[RealtimeDriver] = []
        self._lock = threading.Lock()
        self._wakeup_r, self._wakeup_w = os.pipe()
        os.set_blocking(self._wakeup_r, False)
        self._thread = threading.Thread(target=self._loop, name="realtime-runs", daemon=True)
        self._thread.start()

    def add(self, driver: RealtimeDriver) -> None:
        with self._lock:
            self._drivers.append(driver)
        os.write(self._wakeup_w, b"!")

    def _loop(self) -> None:
        while True:
            with self._lock:
                drivers = list(self._drivers)
            now = time.monotonic()
            due = [d for d in drivers if d.deadline <= now]
            if not due:
                owner = {fd: d for d in drivers for fd in d.fds}
                timeout = min((d.deadline for d in drivers), default=now + 1.0) - now
                readable = _wait_readable([self._wakeup_r, *owner], max(0.0, timeout))
                if self._wakeup_r in readable:
                    with contextlib.suppress(BlockingIOError):
                        os.read(self._wakeup_r, 4096)
                now = time.monotonic()
                due = {owner[fd] for fd in readable if fd in owner}
                due.update(d for d in drivers if d.deadline <= now)
            # Earliest deadline first: a run keeps its place among runs due together, so its
            # wake-ups are late by about the same amount each period instead of by a varying
            # one (which is what a loop period's jitter is made of).
            for driver in sorted(due, key=_deadline):
                self._step(driver)

    def _step(self, driver: RealtimeDriver) -> None:
        try:
            going_on = driver.step()
        except BaseException as error:  # RunEnd, or a fault: it ends this run only
            driver.error = error
            going_on = False
        if not going_on:
            with self._lock:
                self._drivers.remove(driver)
            driver.finished.set()


def _deadline(driver: RealtimeDriver) -> float:
    return driver.deadline


def _wait_readable(fds: list[int], timeout_s: float) -> list[int]:
    """select() has microsecond timeouts (poll() only milliseconds, a 1 ms jitter on every
    wake-up) but cannot watch fd numbers past FD_SETSIZE; fall back to poll() then."""
    if max(fds) < 1024:
        return select.select(fds, [], [], timeout_s)[0]
    poller = select.poll()
    for fd in fds:
        poller.register(fd, select.POLLIN)
    return [fd for fd, _ in poller.poll(timeout_s * 1000.0)]


_scheduler: RealtimeScheduler | None = None
_scheduler_lock = threading.Lock()


def run_realtime(run: ClockedRun) -> None:
    """Drive `run` on the shared realtime scheduler; return (or raise its end) when done."""
    global _scheduler
    # Other threads (recorders writing chunks) hold the GIL for up to the switch interval,
    # 5 ms by default, each time the scheduler wants it back; that lands on wake-ups as
    # lateness. A shorter interval keeps them on time. (Process-wide; lockstep is unaffected.)
    if sys.getswitchinterval() > GIL_SWITCH_INTERVAL_S:
        sys.setswitchinterval(GIL_SWITCH_INTERVAL_S)
    with _scheduler_lock:
        if _scheduler is None:
            _scheduler = RealtimeScheduler()
    driver = RealtimeDriver(run)
    _scheduler.add(driver)
    driver.finished.wait()
    if driver.error is not None:
        raise driver.error
