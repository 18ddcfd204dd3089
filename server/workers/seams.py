"""The two seams of issue 16: what a web process needs of whatever executes its runs
(`RunExecutor`), and where a worker sends a run's live traffic (`LiveOutlet`).

    executor.submit(job)                     # queued; a worker starts it when it has room
    executor.command(run_id, Pause())        # True: taken; False: not running; CommandError
    executor.status(run_id)                  # RunStatus or None (not running any more)
    executor.feed(run_id)                    # RunTelemetry mirror for viewers, or None

Routes, the websocket, the 3D view and the hub still talk only to RunService
(server/service/runs.py), which holds an executor.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from server.runs.commands import RunCommand
from server.service.telemetry import RunTelemetry
from server.workers.wire import LiveBatch, RunJob, RunStatus


class ExecutorUnavailableError(RuntimeError):
    """No worker can take runs now (the queue's Redis is down, every worker is gone); the
    message says what to do. The API answers 503 with it."""


class LiveOutlet(Protocol):
    """Where a worker's RunHost sends each run's live traffic (a pipe to the web process, Redis
    pub/sub, or straight into a RunTelemetry in-process). Called from the host's publisher
    thread, once a round with every run's batch of that round (at most one per run), so an
    outlet can send a round in one write: one pipe message, one Redis round trip. Must not
    block for long and must not raise (a lost batch is logged, the others still go, the run
    goes on: telemetry is latest-wins anyway, and the end is also in the database)."""

    def publish_round(self, batches: Sequence[LiveBatch]) -> None: ...


class RunExecutor(Protocol):
    """Where a web process's RunService sends runs, and how it reaches them while they run."""

    def submit(self, job: RunJob) -> None:
        """Queue the run; raises ExecutorUnavailableError when nothing can take it."""

    def command(self, run_id: str, command: RunCommand) -> bool:
        """Deliver a command to the run wherever it runs. True: taken; False: the run is not
        running (any more, or not yet started); raises CommandError with the run's refusal."""

    def status(self, run_id: str) -> RunStatus | None:
        """The newest status of a running run; None when it is not running."""

    def feed(self, run_id: str) -> RunTelemetry | None:
        """The run's live telemetry, for a websocket viewer or the 3D view (a mirror of the
        worker's traffic); None when this run has none (never ran, or over long ago)."""

    def is_running(self, run_id: str) -> bool:
        """Whether the run is held by a worker (going, or being judged and stored)."""

    def workers(self) -> list[dict]:
        """The workers seen and their capacity: [{"id", "host", "role", "capacity", "running",
        "state", "last_seen_s"}], for the admin page and `/api/admin/status`. `role`: "worker
        process" (one of this machine's), "worker" (a cluster's), or the web process itself,
        "web process: every run" (no workers) or "web process: real robots' runs" (capacity
        None: a robot takes one run at a time, and the web process adds nothing to the sum)."""

    def shutdown(self, grace_s: float) -> None:
        """Stop taking runs. In-process and local-process executors stop their runs ("the
        server is shutting down") and wait up to `grace_s`; the cluster's runs carry on."""
