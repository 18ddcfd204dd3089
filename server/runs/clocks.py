"""The two clocks a run can keep.

*Lockstep* (virtual time, as fast as the machine allows, deterministic): every node sleeps until
a wake time it chose (or, spinning, until a message arrives for it); the simulation advances
from one wake-up to the next, never further than the next sensor message a spinning node may
be waiting for. Nodes due at the same instant wake one after another in launch-file order, and
what one publishes reaches the others at their next wake. Same seed, same code: the same
recording, byte for byte.

*Realtime* (wall clock, real-time factor 1): the simulation keeps advancing while nodes compute,
so a slow controller shows up as latency, as on a real robot. Nodes are woken without waiting
(`begin_wake`) and their replies collected as they come, so one slow node does not hold up the
others; a command takes effect at the moment its reply arrives.
"""

from __future__ import annotations

import select
import sys
import time
from typing import TYPE_CHECKING

from server.runs.state import RunState

if TYPE_CHECKING:
    from server.runs.run import Run

NS = 1_000_000_000
# Two spinning nodes can answer each other forever without time passing; after this many
# wake rounds at one instant, time moves on to the next event.
MAX_ROUNDS_PER_INSTANT = 100
# [s] longest the realtime loop sleeps when nothing is due; controls and node replies wake it
# earlier through their fds, so this only bounds how stale `progress` can look.
REALTIME_IDLE_S = 0.05
GIL_SWITCH_INTERVAL_S = 0.0005  # [s] see run_realtime


def run_lockstep(run: Run) -> None:
    rounds = 0
    order = list(run.slots.values())
    while True:
        run._apply_controls()
        while run.state is RunState.PAUSED:
            run.wait_while_paused(0.1)
        now = run.time_ns
        if now >= run.duration_ns:
            return  # the run covers [0, duration): nothing wakes at its last instant
        due = [
            slot
            for slot in order
            if not slot.done
            and (
                (slot.wake_at_ns is not None and slot.wake_at_ns <= now)
                or (slot.wake_at_ns is None and run.bus.has_pending(slot.name))
            )
        ]
        if due and rounds < MAX_ROUNDS_PER_INSTANT:
            rounds += 1
            for slot in due:
                if not slot.done:
                    run.wake(slot, now)
            continue
        rounds = 0
        run.advance_to(_next_event_ns(run))


def _next_event_ns(run: Run) -> int:
    candidates = [run.duration_ns]
    spinning = False
    for slot in run.slots.values():
        if slot.done:
            continue
        if slot.wake_at_ns is None:
            spinning = True
        else:
            candidates.append(slot.wake_at_ns)
    if spinning:
        # A spinning node wakes on messages: stop where the robot next publishes.
        candidates.append(round(run.sim.next_publication_s() * NS))
    next_ns = min(candidates)
    tick_ns = round(run.sim._tick_s * NS)
    return max(next_ns, run.time_ns + tick_ns)  # always move on by at least one tick


def run_realtime(run: Run) -> None:
    # Many realtime runs share one interpreter; Python hands the GIL over every 5 ms by
    # default, which shows up as periods 5-20 ms late. A shorter interval costs a little
    # throughput and keeps wake-ups on time. (Process-wide, and harmless for lockstep runs.)
    if sys.getswitchinterval() > GIL_SWITCH_INTERVAL_S:
        sys.setswitchinterval(GIL_SWITCH_INTERVAL_S)
    start = time.monotonic()
    order = list(run.slots.values())
    poller = select.poll()
    poller.register(run.control_signal_fd, select.POLLIN)
    watched: set[int] = set()
    while True:
        run._apply_controls()
        now_ns = round((time.monotonic() - start) * NS)
        run.advance_to(min(now_ns, run.duration_ns))
        if run.time_ns >= run.duration_ns:
            return
        for slot in order:
            if slot.done or slot.process is None:
                continue
            if slot.process.state == "running":
                reply = slot.process.poll_reply(0.0)
                if reply is not None:
                    run.handle_reply(slot, reply)
            if slot.done:
                continue
            if slot.process.state == "sleeping" and (
                (slot.wake_at_ns is not None and slot.wake_at_ns <= run.time_ns)
                or (slot.wake_at_ns is None and run.bus.has_pending(slot.name))
            ):
                run.begin_wake(slot, run.time_ns)
        # Sleep until the next thing to do: a node's wake time, the robot's next message, a
        # reply (its fds wake the poll), or a short idle tick to look at controls.
        # (A node still computing is not due: its reply wakes the poll below.)
        next_ns = min(
            [run.duration_ns, round(run.sim.next_publication_s() * NS)]
            + [
                s.wake_at_ns
                for s in order
                if not s.done
                and s.wake_at_ns is not None
                and s.process is not None
                and s.process.state == "sleeping"
            ]
        )
        wait_s = min(REALTIME_IDLE_S, max(0.0, next_ns / NS - (time.monotonic() - start)))
        wanted = {
            fd
            for s in order
            if not s.done and s.process is not None and s.process.state == "running"
            for fd in s.process.reply_fds
        }
        for fd in watched - wanted:
            poller.unregister(fd)
        for fd in wanted - watched:
            poller.register(fd, select.POLLIN)
        watched = wanted
        if wait_s > 0:
            poller.poll(wait_s * 1000.0)
