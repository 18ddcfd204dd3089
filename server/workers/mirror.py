"""The web side of runs executed elsewhere (issue 16): a mirror per run rebuilds, from the
`LiveBatch`es its worker sends, what viewers and routes read of a running run - a RunTelemetry
(server/service/telemetry.py) for websocket viewers and the 3D view, the newest `RunStatus`,
and each node's log lines.

    mirrors = Mirrors()
    mirrors.expect(run_id)          # at submit: a viewer may connect before the first batch
    mirrors.apply(batch)            # from whatever carries batches (a thread, a pipe, Redis)
    mirrors.feed(run_id)            # RunTelemetry for viewers, or None
    mirrors.status(run_id)          # newest RunStatus while running, with the full logs
    mirrors.end(run_id, FAILED, "failed: worker lost")   # its worker is gone

A mirror whose run ended (its final batch, or `end`) answers no status any more and is freed
KEEP_AFTER_END_S later once no viewer holds it, so memory stays flat however many runs pass.
Batches for an ended mirror are ignored: a lost worker's late traffic cannot revive its run.
"""

from __future__ import annotations

import dataclasses
import logging
import threading
import time
from collections import deque

from server.runs.slots import LOG_LINES_KEPT
from server.runs.state import RunState
from server.service.telemetry import KEEP_AFTER_END_S, RunTelemetry
from server.workers.wire import LiveBatch, RunStatus

log = logging.getLogger("robodojo.workers")

SWEEP_EVERY_S = 1.0  # [s] ended mirrors are looked for at most this often
WORKER_LOST = "failed: worker lost"  # the reason of a run whose worker died under it


class Mirror:
    """One run executed elsewhere, as this process knows it."""

    def __init__(self, run_id: str) -> None:
        self.run_id = run_id
        self.telemetry = RunTelemetry(run_id)
        self.status: RunStatus | None = None
        self.logs: dict[str, deque[str]] = {}
        self.ended = False  # the final batch came (or the worker was lost): nothing more will
        self.last_batch_s = time.monotonic()  # [s] monotonic, for whoever watches the worker
        self.lock = threading.Lock()  # apply and end, from different threads

    def apply(self, batch: LiveBatch) -> None:
        with self.lock:
            if self.ended:
                return
            self.last_batch_s = time.monotonic()
            telemetry = self.telemetry
            for sample in batch.samples:
                telemetry.on_sample(
                    sample.topic,
                    sample.type_name,
                    sample.time_ns,
                    sample.data,
                    sample.wall_s,
                    sample.skipped,
                )
            if batch.status is not None:
                self.status = batch.status
                for node, lines in batch.status.logs.items():
                    if node not in self.logs:  # joined late: the status has the newest lines
                        self.logs[node] = deque(lines, maxlen=LOG_LINES_KEPT)
            if batch.final:
                self.ended = True  # before viewers hear the end: is_running is False by then
            self._apply_events(batch.events)
            if batch.final and not telemetry.ended:
                telemetry.on_state(RunState.FAILED, "failed: the run did not end", 0.0)

    def _apply_events(self, events) -> None:
        telemetry = self.telemetry
        node, lines = None, []  # consecutive log lines of one node go together
        for event in events:
            kind = event.get("type")
            if kind == "log" and isinstance(event.get("line"), str):
                if event.get("node") != node and lines:
                    self._logs(node, lines)
                    lines = []
                node = str(event.get("node"))
                lines.append(event["line"])
                continue
            if lines:
                self._logs(node, lines)
                node, lines = None, []
            if kind == "state":
                try:
                    state = RunState(event["state"])
                    telemetry.on_state(state, str(event["reason"]), float(event["time_s"]))
                except (KeyError, TypeError, ValueError):
                    log.warning("run %s: a state event without a state: %r", self.run_id, event)
            else:
                telemetry.on_event(event)
        if lines:
            self._logs(node, lines)

    def _logs(self, node: str, lines: list[str]) -> None:
        kept = self.logs.get(node)
        if kept is None:
            kept = self.logs[node] = deque(maxlen=LOG_LINES_KEPT)
        kept.extend(lines)
        self.telemetry.on_logs(node, lines)

    def end(self, state: RunState, reason: str) -> bool:
        """End the run here (its worker is gone); False when it had ended already."""
        with self.lock:
            if self.ended:
                return False
            self.ended = True
            self.telemetry.on_state(state, reason, self.telemetry.time_s)
            return True

    def running_status(self) -> RunStatus | None:
        """The newest status with every node's kept log lines; None once ended or before the
        first status."""
        with self.lock:
            if self.ended or self.status is None:
                return None
            logs = {node: list(lines) for node, lines in self.logs.items()}
            return dataclasses.replace(self.status, logs=logs)


class Mirrors:
    """run id -> Mirror for the runs this web process follows."""

    def __init__(self, keep_after_end_s: float = KEEP_AFTER_END_S) -> None:
        self.keep_after_end_s = keep_after_end_s
        self._mirrors: dict[str, Mirror] = {}
        self._lock = threading.Lock()
        self._swept_s = time.monotonic()

    def expect(self, run_id: str) -> Mirror:
        """The run's mirror, made now if it has none (a run just submitted)."""
        self._maybe_sweep()
        with self._lock:
            mirror = self._mirrors.get(run_id)
            if mirror is None:
                mirror = self._mirrors[run_id] = Mirror(run_id)
            return mirror

    def apply(self, batch: LiveBatch) -> None:
        """A batch from the run's worker (a run this process never saw gets a mirror)."""
        self.expect(batch.run_id).apply(batch)

    def get(self, run_id: str) -> Mirror | None:
        with self._lock:
            return self._mirrors.get(run_id)

    def feed(self, run_id: str) -> RunTelemetry | None:
        mirror = self.get(run_id)
        return mirror.telemetry if mirror is not None else None

    def status(self, run_id: str) -> RunStatus | None:
        mirror = self.get(run_id)
        return mirror.running_status() if mirror is not None else None

    def is_running(self, run_id: str) -> bool:
        mirror = self.get(run_id)
        return mirror is not None and not mirror.ended

    def end(self, run_id: str, state: RunState, reason: str) -> bool:
        """End a run whose worker was lost (viewers see `reason` live); False when it had ended
        or is unknown here."""
        mirror = self.get(run_id)
        return mirror.end(state, reason) if mirror is not None else False

    def running(self) -> list[str]:
        with self._lock:
            return [run_id for run_id, mirror in self._mirrors.items() if not mirror.ended]

    def run_ids(self) -> list[str]:
        with self._lock:
            return list(self._mirrors)

    def viewer_count(self) -> int:
        with self._lock:
            return sum(mirror.telemetry.viewer_count for mirror in self._mirrors.values())

    def __len__(self) -> int:
        return len(self._mirrors)

    def sweep(self, now_s: float | None = None) -> list[str]:
        """Free ended mirrors past their keep time with no viewer; returns their ids."""
        now_s = time.monotonic() if now_s is None else now_s
        self._swept_s = now_s
        with self._lock:
            expired = [
                run_id
                for run_id, mirror in self._mirrors.items()
                if mirror.ended
                and mirror.telemetry.ended_at_s is not None
                and now_s - mirror.telemetry.ended_at_s >= self.keep_after_end_s
                and mirror.telemetry.viewer_count == 0
            ]
            for run_id in expired:
                del self._mirrors[run_id]
        return expired

    def _maybe_sweep(self) -> None:
        if time.monotonic() - self._swept_s >= SWEEP_EVERY_S:
            self.sweep()
