"""Runs in threads of this process (issue 16): a RunHost whose outlet applies batches straight to
this process's mirrors. For `robodojo run`, the tests, `--workers 0`, and the runs of a robot
whose connection this process holds. Same seam as the other executors, so the web side reads a
run here exactly as it reads one on another process.
"""

from __future__ import annotations

import logging
import socket
import threading
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor

from sandbox.launcher import Launcher
from server.runs.commands import RunCommand
from server.runs.state import RunState
from server.service.telemetry import RunTelemetry
from server.store.db import Store
from server.workers.host import RunHost, default_worker_id
from server.workers.mirror import Mirrors
from server.workers.seams import ExecutorUnavailableError
from server.workers.wire import LiveBatch, RunJob, RunStatus

log = logging.getLogger("robodojo.workers")

# The admin status's "role" of this process's row (RunExecutor.workers in seams.py).
WEB_PROCESS_ALL = "web process: every run"  # --workers 0, robodojo run
WEB_PROCESS_ROBOTS = "web process: real robots' runs"  # beside worker processes


class MirrorOutlet:
    """A LiveOutlet into mirrors of this same process."""

    def __init__(self, mirrors: Mirrors) -> None:
        self.mirrors = mirrors

    def publish_round(self, batches: Sequence[LiveBatch]) -> None:
        for batch in batches:
            self.mirrors.apply(batch)


class InProcessExecutor:
    """A RunExecutor running each run on a thread of this process."""

    def __init__(
        self,
        store: Store,
        settings,
        launcher: Launcher,
        hardware=None,
        mirrors: Mirrors | None = None,
        capacity: int | None = None,
        robots_only: bool = False,
    ) -> None:
        """`robots_only`: only real robots' runs come here (the other runs go to worker
        processes), so the admin status lists this process as what it is, with no capacity of
        its own to add up: a robot takes one run at a time."""
        self.mirrors = mirrors if mirrors is not None else Mirrors()
        self.robots_only = robots_only
        self.capacity = capacity if capacity is not None else settings.max_runs_total
        self.host = RunHost(
            store, settings, launcher, MirrorOutlet(self.mirrors), default_worker_id(), hardware
        )
        self._pool = ThreadPoolExecutor(max_workers=max(1, self.capacity), thread_name_prefix="run")
        self._closing = False
        self._lock = threading.Lock()

    def submit(self, job: RunJob) -> None:
        with self._lock:
            if self._closing:
                raise ExecutorUnavailableError("the server is shutting down; try again in a minute")
            self.mirrors.expect(job.run_id)
            self.host.accept(job)  # commands sent as soon as the run is created reach it
            self._pool.submit(self._execute, job)

    def _execute(self, job: RunJob) -> None:
        try:
            self.host.execute(job)
        except BaseException as error:  # execute() does not raise; if it does, this run ends
            log.exception("run %s raised out of RunHost.execute()", job.run_id)
            self.mirrors.end(job.run_id, RunState.FAILED, f"failed: internal error ({error!r})")
            raise

    def command(self, run_id: str, command: RunCommand) -> bool:
        return self.host.command(run_id, command)

    def status(self, run_id: str) -> RunStatus | None:
        return self.host.status(run_id)  # read now: the run is right here

    def feed(self, run_id: str) -> RunTelemetry | None:
        return self.mirrors.feed(run_id)

    def is_running(self, run_id: str) -> bool:
        return self.mirrors.is_running(run_id)

    def running(self) -> list[str]:
        return self.mirrors.running()

    def workers(self) -> list[dict]:
        return [
            {
                "id": self.host.worker_id,
                "host": socket.gethostname(),
                "role": WEB_PROCESS_ROBOTS if self.robots_only else WEB_PROCESS_ALL,
                "capacity": None if self.robots_only else self.capacity,
                "running": len(self.host.running()),
                "state": "closing" if self._closing else "up",
                "last_seen_s": 0.0,
            }
        ]

    def shutdown(self, grace_s: float) -> None:
        with self._lock:
            self._closing = True
        self.host.close(grace_s)
        self._pool.shutdown(wait=False, cancel_futures=True)
