"""A run's outbox on its worker (issue 16): the run's observer (server.runs.outputs.RunObserver),
holding what the run produced since its previous LiveBatch - the newest sample per topic (the
overwritten ones counted as `skipped`), its events in order, whether a status is due - until
the host's publisher (server/workers/host.py) takes it. Called on the run's thread: quick,
never blocking on the outlet. Non-end state changes are stored here as they happen; the end is
held back until the run is stored and judged.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import Any

from sandbox.services import is_internal
from server.runs.state import RunState
from server.service.telemetry import EVENTS_KEPT
from server.store import runs as run_store
from server.store.db import Store
from server.workers.wire import Sample

log = logging.getLogger("robodojo.workers")

OUTBOX_EVENTS = EVENTS_KEPT  # events held per run between two rounds; more are counted dropped
# [s] a running run's status snapshot, besides one at each state change. It is what GET
# /api/runs/{id} answers (the page polls that once a second; its figures are recomputed once a
# second): 0.2 s sent each 2.5 KB status five times for every time it was read, the largest part
# of the live traffic's JSON (33 us to write, 20 us to read, per status).
STATUS_EVERY_S = 0.5


class Outbox:
    """A run's observer on the worker (server.runs.outputs.RunObserver): what it produced since
    its previous batch. Called on the run's thread; quick and never blocking on the outlet."""

    def __init__(self, store: Store, run_id: str, wake: Callable[[], None]) -> None:
        self._store = store
        self._wake = wake  # the publisher's: something is waiting to go out
        self._run_id = run_id
        self._lock = threading.Lock()
        self._samples: dict[str, Sample] = {}
        self._events: list[dict[str, Any]] = []
        self._dropped_events = 0
        self.status_due = True  # the first round sends a status
        self.next_status_s = 0.0  # [s] monotonic
        self.end: tuple[RunState, str, float] | None = None  # held back until stored and judged
        self.finished = False  # the end events are in: the next batch is the final one

    def on_message(self, topic: str, type_name: str, time_ns: int, data: bytes) -> None:
        if is_internal(topic):
            return  # a service's request/answer topics: in the recording, not for viewers
        wall_s = time.time()
        with self._lock:
            previous = self._samples.get(topic)
            skipped = previous.skipped + 1 if previous is not None else 0
            self._samples[topic] = Sample(topic, type_name, time_ns, data, wall_s, skipped)
        self._wake()

    def on_logs(self, node: str, lines: list[str]) -> None:
        self._append([{"type": "log", "node": node, "line": line} for line in lines])

    def on_state(self, state: RunState, reason: str, time_s: float) -> None:
        if state.is_end:
            # Viewers hear of the end after the results are stored and the checks judged, so
            # the check results reach them before the end.
            self.end = (state, reason, time_s)
            return
        try:
            with self._store.session() as db:
                run_store.set_state(db, self._run_id, str(state))
        except Exception:
            log.exception("run %s: could not store state %s", self._run_id, state)
        event = {"type": "state", "state": str(state), "reason": reason, "time_s": time_s}
        with self._lock:
            self.status_due = True
        self._append([event])

    def _append(self, events: list[dict[str, Any]]) -> None:
        with self._lock:
            self._events.extend(events)
            overflow = len(self._events) - OUTBOX_EVENTS
            if overflow > 0:  # a flood of prints faster than a round: the oldest go
                del self._events[:overflow]
                self._dropped_events += overflow
        self._wake()

    def finish(self, events: list[dict[str, Any]]) -> None:
        with self._lock:
            self._events.extend(events)
            self.finished = True
        self._wake()

    def take(self, now_s: float) -> tuple[tuple[Sample, ...], tuple[dict, ...], bool, bool]:
        """(samples, events, status due, final) since the previous take."""
        with self._lock:
            samples = tuple(self._samples.values())
            self._samples = {}
            events = self._events
            self._events = []
            if self._dropped_events:
                dropped = {"type": "dropped", "what": "events", "count": self._dropped_events}
                events.insert(0, dropped)
                self._dropped_events = 0
            final = self.finished
            status_due = self.status_due or now_s >= self.next_status_s or final
            self.status_due = False
        if status_due:
            self.next_status_s = now_s + STATUS_EVERY_S
        return samples, tuple(events), status_due, final
