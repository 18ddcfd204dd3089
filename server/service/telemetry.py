"""Live telemetry of one run for its websocket viewers: latest value wins, nothing queues.

A run publishes far faster than a browser can draw and a viewer on a slow link can take, so
nothing is kept per message per viewer (viser's redundancy keys, taken to the end):

* per topic, only the latest sample; a viewer subscribes with a maximum rate, is sent the
  newest sample whenever its rate allows, and each frame says how many samples were
  overwritten since the last one it got (``dropped``);
* log lines and state changes go into one bounded ring of events with a global sequence
  number; a viewer that fell behind the ring is told how many events it missed.

Threads: the run calls ``on_message``/``on_logs``/``on_state`` on its own worker thread
(``server.runs.outputs.RunObserver``); viewers live on the asyncio loop of the websocket. The run
thread never blocks on a viewer: it swaps in the newest sample and, at most once per viewer
until that viewer has woken, schedules a wake-up on the viewer's loop.

    telemetry = registry.create(run_id)          # Run(..., observer=telemetry)
    viewer = telemetry.viewer()                  # inside the websocket's loop
    viewer.subscribe("scan", max_rate_hz=10)
    while not viewer.finished:
        for frame in await viewer.next_frames(timeout_s=1.0):
            await websocket.send_json(frame)
    viewer.close()
"""

from __future__ import annotations

import asyncio
import contextlib
import math
import threading
import time
from collections import deque
from dataclasses import dataclass
from itertools import islice
from typing import Any

from sandbox import names
from sandbox.services import is_internal
from server.runs.state import RunState
from server.service.decode import decode

# Limits, each bounding memory or work that a run or a client could otherwise grow.
EVENTS_KEPT = 2000  # log lines + state changes per run; a viewer further behind is told so
MAX_RATE_HZ = 60.0  # [Hz] per subscription: a browser repaints at 60 Hz, faster is wasted
MAX_SUBSCRIPTIONS = 64  # per viewer: more topics than any robot here has
MAX_TOPIC_CHARS = 256  # a topic name longer than this is a client bug, not a topic
MAX_VIEWERS_PER_RUN = 256  # a class watching one demo run; each costs a wake-up per message
LATENCIES_KEPT = 10_000  # delivery latency samples per run, for p50/p99 in benchmarks
VIEWER_LATENCIES_KEPT = 1_000  # per viewer: 100 viewers must not hold a million floats
RATE_BURST = 0.5  # [frames] a late frame may be followed this much sooner than one period
KEEP_AFTER_END_S = 300.0  # [s] a viewer reconnecting after a blip still sees how it ended


class SubscriptionError(ValueError):
    """A subscribe/unsubscribe request a viewer cannot have; the message says what to send."""


class ViewerLimitError(RuntimeError):
    """The run already has as many live viewers as it serves."""


class UnknownRunError(KeyError):
    """No live telemetry for this run id."""

    def __str__(self) -> str:  # KeyError would show the sentence in quotes
        return str(self.args[0])


@dataclass(slots=True)
class _Sample:
    """The latest message on a topic. Replaced whole, never mutated, except for the decoded
    form, which the first viewer to send it fills in for all the others."""

    seq: int  # per topic, from 1
    type_name: str
    time_ns: int  # [ns] run clock
    data: bytes
    received_s: float  # [s] time.monotonic() when the run handed it over
    produced_wall_s: float  # [s] time.time() when the run produced it (on whichever machine)
    decoded: dict[str, Any] | None = None
    error: str | None = None


@dataclass(slots=True)
class _Subscription:
    period_s: float  # [s] 1 / max rate
    sent_seq: int  # the topic's seq last sent (or current when subscribing, minus one)
    next_allowed_s: float = 0.0  # [s] monotonic; no frame on this topic before then


class RunTelemetry:
    """The live side of one run: a RunObserver for the run, a source of Viewers for websockets."""

    def __init__(self, run_id: str) -> None:
        self.run_id = run_id
        self.state = RunState.CREATED
        self.reason = ""
        self.time_s = 0.0  # [s] run clock at the last state change
        self.ended_at_s: float | None = None  # [s] monotonic, once the state is an end state
        self._latest: dict[str, _Sample] = {}
        self._topics: dict[str, str] = {}  # name -> message type, in order of first message
        self._lock = threading.Lock()  # events, topics and state; never held while waking
        self._events: deque[dict[str, Any]] = deque(maxlen=EVENTS_KEPT)
        self._event_seq = 0  # seq of the newest event; the ring holds the last len() of them
        self._viewers: tuple[Viewer, ...] = ()  # replaced whole, so the run thread can iterate
        self._latencies_s: deque[float] = deque(maxlen=LATENCIES_KEPT)

    # ------------------------------------------------------------------- RunObserver (run thread)
    def on_message(
        self,
        topic: str,
        type_name: str,
        time_ns: int,
        data: bytes,
        produced_wall_s: float | None = None,
    ) -> None:
        """`produced_wall_s`: time.time() when the run produced the message, given by a mirror
        of a run elsewhere (a worker's Sample.wall_s); now, when the run calls directly."""
        if produced_wall_s is None:
            self._put(topic, type_name, time_ns, data, time.monotonic(), time.time(), 0)
        else:
            self.on_sample(topic, type_name, time_ns, data, produced_wall_s, 0)

    def on_sample(
        self,
        topic: str,
        type_name: str,
        time_ns: int,
        data: bytes,
        produced_wall_s: float,
        skipped: int,
    ) -> None:
        """A sample of a run elsewhere (server/workers/mirror.py): the newest on its topic when
        the worker sent it, `skipped` older ones overwritten there, so a viewer's `dropped`
        count stays true. Its delivery latency counts from when the worker produced it
        (`produced_wall_s`, time.time() on a machine sharing this clock), not from now."""
        waited_s = min(max(0.0, time.time() - produced_wall_s), 3600.0)
        self._put(
            topic, type_name, time_ns, data, time.monotonic() - waited_s, produced_wall_s, skipped
        )

    def _put(
        self,
        topic: str,
        type_name: str,
        time_ns: int,
        data: bytes,
        received_s: float,
        produced_wall_s: float,
        skipped: int,
    ) -> None:
        if is_internal(topic):
            return  # a service's request/answer topics: in the recording, not for plots
        previous = self._latest.get(topic)
        if previous is None:
            with self._lock:
                self._topics[topic] = type_name
                self._append_event({"type": "topic", "topic": topic, "msg_type": type_name})
            seq = 1 + max(0, skipped)
        else:
            seq = previous.seq + 1 + max(0, skipped)
        self._latest[topic] = _Sample(seq, type_name, time_ns, data, received_s, produced_wall_s)
        for viewer in self._viewers:
            if previous is None or topic in viewer._subscriptions:
                viewer._poke()

    def on_logs(self, node: str, lines: list[str]) -> None:
        with self._lock:
            skipped = max(0, len(lines) - EVENTS_KEPT)  # they would fall out of the ring at once
            self._event_seq += skipped
            for line in islice(lines, skipped, None):
                self._append_event({"type": "log", "node": node, "line": line})
        self._poke_all()

    def on_state(self, state: RunState, reason: str, time_s: float) -> None:
        with self._lock:
            self.reason = reason
            self.time_s = time_s
            self._append_event(
                {"type": "state", "state": str(state), "reason": reason, "time_s": time_s}
            )
            self.state = state
            if state.is_end:
                self.ended_at_s = time.monotonic()
        self._poke_all()

    def on_event(self, event: dict[str, Any]) -> None:
        """Any other JSON-able event for viewers (an exercise's check results, say)."""
        with self._lock:
            self._append_event(event)
        self._poke_all()

    def _append_event(self, event: dict[str, Any]) -> None:  # with self._lock held
        self._event_seq += 1
        self._events.append(event)

    def _poke_all(self) -> None:
        for viewer in self._viewers:
            viewer._poke()

    # ----------------------------------------------------------------------- viewers (loop side)
    def viewer(self) -> Viewer:
        """A new viewer bound to the running asyncio loop; ``close()`` it when the socket ends."""
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:
            raise RuntimeError(
                "RunTelemetry.viewer() must be called inside the websocket's asyncio loop "
                "(from a coroutine), since the viewer is woken on that loop"
            ) from None
        with self._lock:
            if len(self._viewers) >= MAX_VIEWERS_PER_RUN:
                raise ViewerLimitError(
                    f"run {self.run_id} already has {MAX_VIEWERS_PER_RUN} live viewers; "
                    "watch its recording once it ends"
                )
            viewer = Viewer(self, loop, self._event_seq - len(self._events))
            self._viewers = (*self._viewers, viewer)
        return viewer

    def _remove(self, viewer: Viewer) -> None:
        with self._lock:
            self._viewers = tuple(other for other in self._viewers if other is not viewer)

    @property
    def viewer_count(self) -> int:
        return len(self._viewers)

    @property
    def ended(self) -> bool:
        return self.state.is_end

    def snapshot(self) -> dict[str, Any]:
        """What a client needs first: the state, why, and the topics seen so far with types."""
        with self._lock:
            return {
                "type": "snapshot",
                "run_id": self.run_id,
                "state": str(self.state),
                "reason": self.reason,
                "time_s": self.time_s,
                "topics": dict(self._topics),
            }

    def delivery_latencies(self) -> list[float]:
        """[s] from a message reaching ``on_message`` to its frame being handed to a viewer,
        the newest LATENCIES_KEPT over all viewers."""
        return list(self._latencies_s)

    def delivery_latency_summary(self) -> dict[str, float | int | None]:
        """Count, p50, p99 and max of ``delivery_latencies()`` [s] (None while empty)."""
        return latency_summary(self._latencies_s)

    def _events_after(self, cursor: int) -> tuple[int, int, list[dict[str, Any]], bool]:
        """(newest seq, count missed, events, ended) for a viewer that has seen events up to
        cursor; ended and the events are read together, so an end state comes with its event."""
        with self._lock:
            newest, ended = self._event_seq, self.state.is_end
            if newest <= cursor:
                return newest, 0, [], ended
            first = newest - len(self._events) + 1  # seq of the oldest event in the ring
            missed = max(0, first - (cursor + 1))
            start = cursor + 1 + missed - first
            return newest, missed, list(islice(self._events, start, None)), ended


class Viewer:
    """One websocket client of a run: its subscriptions, what it has been sent, its wake-up.

    All methods but ``_poke`` run on the viewer's asyncio loop.
    """

    def __init__(self, telemetry: RunTelemetry, loop: asyncio.AbstractEventLoop, cursor: int):
        self.telemetry = telemetry
        self._loop = loop
        self._event_cursor = cursor  # seq of the last event handed out
        self._subscriptions: dict[str, _Subscription] = {}
        self._event = asyncio.Event()
        self._wake_pending = False  # a _wake is scheduled on the loop and has not run yet
        self._closed = False
        self._finished = False
        self.latencies_s: deque[float] = deque(maxlen=VIEWER_LATENCIES_KEPT)

    # ----------------------------------------------------------------------------- subscriptions
    def subscribe(self, topic: str, max_rate_hz: float) -> None:
        """Send ``topic``'s newest sample at most ``max_rate_hz`` times a second. A topic with
        no messages yet is fine (it may start later); subscribing again changes the rate.
        ``topic`` is read as a global ROS name: "/scan" is the bus's "scan" (`_bus_name`)."""
        if self._closed:
            raise SubscriptionError("this viewer is closed; open a new one to subscribe")
        topic = _bus_name(topic)
        if isinstance(max_rate_hz, bool) or not isinstance(max_rate_hz, int | float):
            raise SubscriptionError(
                f"max_rate_hz is a number of frames per second, got {max_rate_hz!r}"
            )
        if not (math.isfinite(max_rate_hz) and 0 < max_rate_hz <= MAX_RATE_HZ):
            raise SubscriptionError(
                f"max_rate_hz must be above 0 and at most {MAX_RATE_HZ:g} Hz, got {max_rate_hz!r}"
            )
        current = self._subscriptions.get(topic)
        if current is not None:
            current.period_s = 1.0 / max_rate_hz
            return
        if len(self._subscriptions) >= MAX_SUBSCRIPTIONS:
            raise SubscriptionError(
                f"a viewer may subscribe to at most {MAX_SUBSCRIPTIONS} topics; "
                "unsubscribe from one first"
            )
        # Registered before reading the latest seq, so a message arriving in between pokes us.
        subscription = _Subscription(1.0 / max_rate_hz, sent_seq=0)
        self._subscriptions[topic] = subscription
        latest = self.telemetry._latest.get(topic)
        if latest is not None:  # send the current value at once; count drops from here on
            subscription.sent_seq = latest.seq - 1
        self._event.set()

    def unsubscribe(self, topic: str) -> None:
        if self._subscriptions.pop(_bus_name(topic), None) is None:
            subscribed = ", ".join(sorted(self._subscriptions)) or "none"
            raise SubscriptionError(f"not subscribed to {topic!r}; subscribed topics: {subscribed}")

    @property
    def subscriptions(self) -> dict[str, float]:
        """Topic -> max rate [Hz]."""
        return {topic: 1.0 / sub.period_s for topic, sub in self._subscriptions.items()}

    # ----------------------------------------------------------------------------- frames
    @property
    def finished(self) -> bool:
        """Nothing more will come: the run ended and everything was handed out, or closed."""
        return self._finished or self._closed

    async def next_frames(self, timeout_s: float) -> list[dict[str, Any]]:
        """Wait up to ``timeout_s`` for something to send and return it as JSON-able frames
        (an empty list on timeout or once finished). A subscribed topic that changed while its
        rate forbids a frame is sent when the rate next allows it, not forgotten."""
        deadline_s = time.monotonic() + timeout_s
        while not self.finished:
            self._event.clear()
            now_s = time.monotonic()
            frames, due_s, ended = self._collect(now_s)
            if ended and self._event_cursor >= self.telemetry._event_seq:
                self._finished = True  # an ended run flushes every topic: nothing is due later
            if frames or self._finished:
                return frames
            wait_s = deadline_s - now_s
            if wait_s <= 0:
                return []
            if due_s is not None:
                wait_s = min(wait_s, due_s - now_s)
            try:
                async with asyncio.timeout(wait_s):
                    await self._event.wait()
            except TimeoutError:
                pass
        return []

    def _collect(self, now_s: float) -> tuple[list[dict[str, Any]], float | None, bool]:
        """Frames due now, when the earliest held-back topic becomes due, and whether the run
        had ended when the events were read.

        Once the run has ended, each topic's last sample goes out at once, rate or not: the
        final values arrive with the end, before its state frame, however low the viewer's rate
        (one extra frame per topic, once)."""
        newest, missed, events, ended = self.telemetry._events_after(self._event_cursor)
        frames: list[dict[str, Any]] = []
        due_s: float | None = None
        latest = self.telemetry._latest
        for topic, subscription in self._subscriptions.items():
            sample = latest.get(topic)
            if sample is None or sample.seq <= subscription.sent_seq:
                continue
            if now_s < subscription.next_allowed_s and not ended:
                if due_s is None or subscription.next_allowed_s < due_s:
                    due_s = subscription.next_allowed_s
                continue
            frames.append(self._telemetry_frame(topic, sample, subscription))
            subscription.sent_seq = sample.seq
            # A schedule, not "one period after the last send": a topic published at the
            # viewer's own rate then goes out as it arrives instead of waiting up to a period
            # for each sample (the arrival jitter would otherwise make the wait random, 0-50 ms
            # at 20 Hz). Never more than RATE_BURST frames above the rate over any stretch.
            subscription.next_allowed_s = (
                max(subscription.next_allowed_s, now_s - RATE_BURST * subscription.period_s)
                + subscription.period_s
            )
            latency_s = time.monotonic() - sample.received_s
            self.latencies_s.append(latency_s)
            self.telemetry._latencies_s.append(latency_s)
        self._event_cursor = newest
        if missed:
            frames.append({"type": "dropped", "what": "events", "count": missed})
        frames.extend(events)
        return frames, due_s, ended

    @staticmethod
    def _telemetry_frame(topic: str, sample: _Sample, sub: _Subscription) -> dict[str, Any]:
        if sample.decoded is None and sample.error is None:
            try:
                sample.decoded = decode(sample.type_name, sample.data)
            except Exception as error:  # bytes the run recorded but we cannot show
                sample.error = f"cannot decode {sample.type_name}: {error}"
        frame = {
            "type": "telemetry",
            "topic": topic,
            "msg_type": sample.type_name,
            "time_s": sample.time_ns / 1e9,
            "msg": sample.decoded,
            "dropped": sample.seq - sub.sent_seq - 1,
            # Production time on the run's machine: delivery latency end to end for whoever
            # shares its clock (bench/bench_cluster.py); a browser may ignore it.
            "wall_s": sample.produced_wall_s,
        }
        if sample.error is not None:
            frame["error"] = sample.error
        return frame

    # ----------------------------------------------------------------------------- wake-up
    def _poke(self) -> None:
        """From the run thread: make sure the viewer wakes. At most one wake-up in flight, so a
        1 kHz topic costs one call_soon_threadsafe per wake, not per message."""
        if self._wake_pending or self._closed:
            return
        self._wake_pending = True
        # RuntimeError: the loop has closed, so the socket is gone and close() will follow.
        with contextlib.suppress(RuntimeError):
            self._loop.call_soon_threadsafe(self._wake)

    def _wake(self) -> None:
        self._wake_pending = False  # before set(): a message after this pokes again
        self._event.set()

    def close(self) -> None:
        """Unregister from the run; a waiting ``next_frames`` returns at once."""
        if not self._closed:
            self._closed = True
            self.telemetry._remove(self)
            self._event.set()


class TelemetryRegistry:
    """run id -> RunTelemetry for the runs this server has live. An ended run's telemetry is
    kept KEEP_AFTER_END_S after its end, and for as long as a viewer is still attached."""

    def __init__(self, keep_after_end_s: float = KEEP_AFTER_END_S) -> None:
        self.keep_after_end_s = keep_after_end_s
        self._runs: dict[str, RunTelemetry] = {}
        self._lock = threading.Lock()

    def create(self, run_id: str) -> RunTelemetry:
        self.sweep()
        with self._lock:
            if run_id in self._runs:
                raise ValueError(f"run {run_id} already has live telemetry; run ids are unique")
            telemetry = self._runs[run_id] = RunTelemetry(run_id)
            return telemetry

    def get(self, run_id: str) -> RunTelemetry:
        self.sweep()
        with self._lock:
            telemetry = self._runs.get(run_id)
        if telemetry is None:
            raise UnknownRunError(
                f"run {run_id} has no live telemetry: it is not running on this server or "
                f"ended more than {self.keep_after_end_s:g} s ago; its recording has the data"
            )
        return telemetry

    def discard(self, run_id: str) -> None:
        with self._lock:
            self._runs.pop(run_id, None)

    def sweep(self, now_s: float | None = None) -> list[str]:
        """Drop ended runs past their keep time with no viewer; returns their ids."""
        now_s = time.monotonic() if now_s is None else now_s
        with self._lock:
            expired = [
                run_id
                for run_id, telemetry in self._runs.items()
                if telemetry.ended_at_s is not None
                and now_s - telemetry.ended_at_s >= self.keep_after_end_s
                and telemetry.viewer_count == 0
            ]
            for run_id in expired:
                del self._runs[run_id]
        return expired

    def run_ids(self) -> list[str]:
        with self._lock:
            return list(self._runs)

    def viewer_count(self) -> int:
        """Live viewers over every run."""
        with self._lock:
            return sum(telemetry.viewer_count for telemetry in self._runs.values())


def latency_summary(latencies_s: Any) -> dict[str, float | int | None]:
    """count, p50_s, p99_s and max_s of latency samples [s] (nearest-rank percentiles)."""
    ordered = sorted(latencies_s)
    if not ordered:
        return {"count": 0, "p50_s": None, "p99_s": None, "max_s": None}

    def rank(fraction: float) -> float:
        return ordered[min(len(ordered) - 1, math.ceil(fraction * len(ordered)) - 1)]

    return {"count": len(ordered), "p50_s": rank(0.5), "p99_s": rank(0.99), "max_s": ordered[-1]}


def _bus_name(topic: Any) -> str:
    """The run's bus name of a topic a viewer names, or SubscriptionError with a sentence.

    The bus names root topics without the leading slash (sandbox/names.py): a viewer stands in
    the root namespace, where rospy resolves "/scan" and "scan" to the same topic, and students
    copy names from `rostopic list`, which prints "/scan". So "/scan" subscribes to "scan" and
    its frames say "scan", as the snapshot's topics do; repeated and trailing slashes go, as
    rosgraph's canonical form drops them ("//ultrasonic//range_0/" -> "ultrasonic/range_0")."""
    if not isinstance(topic, str) or not topic:
        raise SubscriptionError(f"a topic is a non-empty name such as 'scan', got {topic!r}")
    if len(topic) > MAX_TOPIC_CHARS or not topic.isprintable() or any(c.isspace() for c in topic):
        raise SubscriptionError(
            f"{topic[:40]!r}... is not a topic name: at most {MAX_TOPIC_CHARS} printable "
            "characters without spaces, such as 'scan' or '/ultrasonic/range_0'"
        )
    name = names.bus_name(names.canonicalize(topic))
    if not name:
        raise SubscriptionError(f"{topic!r} names no topic; name one such as 'scan'")
    return name
