"""The cluster's executor: a web process started with `--redis-url` runs no run itself; it
queues each run as a Dramatiq job for the `robodojo worker` processes (queue.py), reaches the
run through Redis while it runs (redis_live.py), and keeps the roster honest: a worker that
stopped reporting has its runs ended "failed: worker lost" and their viewers told (issue 16).

    executor = QueueExecutor(store, redis_url, mirror)     # mirror: server/workers/mirror.py
    executor.submit(job)                                   # RunService does this
    executor.command(run_id, Pause())                      # True / False / CommandError
    executor.feed(run_id)                                  # a RunTelemetry fed from Redis

Any number of web processes may stand side by side: none holds state another needs. Each
follows, on demand, only the runs someone watches or asks about through it.
"""

from __future__ import annotations

import contextlib
import logging
import threading
import time
from typing import Protocol

import redis

from server.runs.commands import CommandError, EmergencyStop, RunCommand, Stop
from server.runs.state import RunState
from server.service.telemetry import RunTelemetry
from server.store import runs as run_store
from server.store import workers as roster
from server.store.db import Store
from server.workers import queue
from server.workers.redis_live import (
    PREFIX,
    LiveSubscriber,
    publish_end,
    run_key,
    send_command,
)
from server.workers.wire import LiveBatch, RunJob, RunStatus

log = logging.getLogger("robodojo.workers.cluster")

# Timing of the web side, each with why.
FIRST_SNAPSHOT_WAIT_S = 2.0  # [s] a status/feed asked for the first time waits this long for
# what Redis keeps of the run (normally ~1 ms)
SILENT_RUN_CHECK_S = 10.0  # [s] a watched run that sent nothing this long is looked up in the
# database: if it ended (Redis lost its final batch), its viewers are told from there
QUEUE_LOST_AFTER_S = 30.0  # [s] a queued run whose job is no longer in Redis (restarted without
# its data) is failed with a sentence after this long, instead of waiting forever
STOP_QUEUED_TRIES = 10  # a stop for a run claimed while it was being stopped is sent again
STOP_QUEUED_WAIT_S = 0.2  # [s] between two tries: a claimed run listens within milliseconds
QUEUE_LOST = "failed: the run queue lost this run (its Redis restarted); start it again"


class Mirror(Protocol):
    """The web side's copy of running runs (server/workers/mirror.py)."""

    def apply(self, batch: LiveBatch) -> None: ...

    def feed(self, run_id: str) -> RunTelemetry | None: ...

    def status(self, run_id: str) -> RunStatus | None: ...

    def expect(self, run_id: str) -> object: ...

    def end(self, run_id: str, state: RunState, reason: str) -> bool: ...


def stop_reason(command: Stop | EmergencyStop) -> str:
    """The reason a run stopped while queued ends with: the one a running run gives
    (server/runs/controls.py)."""
    return f"interrupted: {command.reason}"


def queued_key(run_id: str) -> str:
    """Set while a run's job waits on the queue; its worker removes it when it claims the run."""
    return f"{PREFIX}queued:{run_id}"


def worker_key(worker_id: str) -> str:
    """A worker's report, renewed every REPORT_PERIOD_S with a short life: it is alive even
    when the database cannot hear from it."""
    return f"{PREFIX}worker:{worker_id}"


class QueueExecutor:
    """RunExecutor for the cluster (seams.py)."""

    def __init__(self, store: Store, redis_url: str, mirror: Mirror) -> None:
        self.store = store
        self.mirror = mirror
        self.client = queue.redis_client(redis_url)
        self.broker = queue.make_broker(redis_url)
        self.live = LiveSubscriber(self.client, self._apply)
        self._last_heard: dict[str, float] = {}  # run -> monotonic time of its newest batch
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._keeper = threading.Thread(target=self._keep, name="cluster-roster", daemon=True)
        self.live.start()
        self._keeper.start()

    # ------------------------------------------------------------------------------ RunExecutor
    def submit(self, job: RunJob) -> None:
        with contextlib.suppress(redis.RedisError):  # then enqueue says so with a sentence
            self.client.set(queued_key(job.run_id), job.queued_wall_s or time.time())
        queue.enqueue(self.broker, job)

    def command(self, run_id: str, command: RunCommand) -> bool:
        for _ in range(STOP_QUEUED_TRIES):
            answer = send_command(self.client, run_id, command)
            if answer is not None:
                if answer.refusal:
                    raise CommandError(answer.refusal)
                return answer.taken
            if not isinstance(command, Stop | EmergencyStop):
                return False
            # No worker holds it: still queued, the stop is written on its record (a worker
            # that fetches it later finds it ended and drops it); else it was claimed just now
            # and listens for commands within moments, or it has ended.
            state = self._stop_queued(run_id, stop_reason(command))
            if state is None:
                return True
            if RunState(state).is_end:
                return False
            time.sleep(STOP_QUEUED_WAIT_S)
        return False

    def _stop_queued(self, run_id: str, reason: str) -> str | None:
        """Interrupt a run still waiting on the queue: None when done, else its state."""
        with self.store.session() as db:
            ended = run_store.end_queued(db, run_id, str(RunState.INTERRUPTED), reason)
            record = None if ended else run_store.get(db, run_id)
        if ended:
            self._tell_end(run_id, str(RunState.INTERRUPTED), reason)
            return None
        return record.state if record is not None else str(RunState.FAILED)

    def status(self, run_id: str) -> RunStatus | None:
        status = self.mirror.status(run_id)
        if status is None and self._follow(run_id):
            status = self.mirror.status(run_id)
        if status is None or RunState(status.state).is_end:
            return None
        return status

    def feed(self, run_id: str) -> RunTelemetry | None:
        feed = self.mirror.feed(run_id)
        if feed is not None:
            self._follow(run_id)  # a no-op once following (or after the end)
            return feed
        if not self._follow(run_id):
            return None
        return self.mirror.feed(run_id)

    def is_running(self, run_id: str) -> bool:
        try:
            meta = self.client.hmget(run_key(run_id), ["seq", "final"])
        except redis.RedisError:
            status = self.mirror.status(run_id)
            return status is not None and not RunState(status.state).is_end
        return meta[0] is not None and meta[1] is None

    def workers(self) -> list[dict]:
        with self.store.session() as db:
            return roster.listing(db)

    def waiting(self) -> int:
        """Simulated runs queued and not yet taken by a worker."""
        try:
            return queue.queued_count(self.broker)
        except redis.RedisError:
            return 0

    def shutdown(self, grace_s: float) -> None:
        """Stop following runs and close Redis; the runs carry on on their workers."""
        self._stop.set()
        self.live.stop()
        self._keeper.join(timeout=grace_s)
        queue.close_broker(self.broker)
        self.client.close()

    # ------------------------------------------------------------------------------ following
    def _follow(self, run_id: str) -> bool:
        """Follow a run's live traffic here: True for a run Redis knows or not yet ended (its
        mirror fills when the subscription is confirmed, normally within milliseconds; this
        waits up to FIRST_SNAPSHOT_WAIT_S for that, no longer: a loaded machine is slower).
        False for a run Redis does not know that has ended (long over) or is unknown, or Redis
        away. A run a worker has claimed ("starting") but not yet published counts as not
        ended: a viewer arriving then used to be told at once that the run was over."""
        try:
            known = self.client.exists(run_key(run_id))
        except redis.RedisError:
            return False
        if not known:  # queued, or claimed by a worker that has not published yet
            with self.store.session() as db:
                record = run_store.get(db, run_id)
                if record is None or RunState(record.state).is_end:
                    return False
        with self._lock:
            self._last_heard.setdefault(run_id, time.monotonic())
        self.live.watch(run_id, wait_s=FIRST_SNAPSHOT_WAIT_S)
        self.mirror.expect(run_id)  # a viewer may attach now; the snapshot fills it
        return True

    def _apply(self, batch: LiveBatch) -> None:  # the subscriber's thread
        with self._lock:
            if batch.final:
                self._last_heard.pop(batch.run_id, None)
            else:
                self._last_heard[batch.run_id] = time.monotonic()
        self.mirror.apply(batch)

    # ------------------------------------------------------------------------------ roster
    def _keep(self) -> None:
        while not self._stop.wait(roster.REPORT_PERIOD_S):
            try:
                self._reap()
                self._check_silent_runs()
                self._check_lost_queue()
            except Exception:  # the database or Redis away: said by them; tried again
                log.warning("the cluster's roster check failed; trying again", exc_info=True)

    def _reap(self) -> None:
        with self.store.session() as db:
            ended = roster.reap(db, alive=self._alive)
        for run_id in ended:
            log.warning("run %s: its worker was lost; the run failed", run_id)
            self._tell_end(run_id, str(RunState.FAILED), roster.WORKER_LOST)

    def _alive(self, worker_id: str) -> bool:
        try:
            return bool(self.client.exists(worker_key(worker_id)))
        except redis.RedisError:
            return False  # the database is the only witness left

    def _tell_end(self, run_id: str, state: str, reason: str) -> None:
        with contextlib.suppress(redis.RedisError):  # others look it up when it goes silent
            publish_end(self.client, run_id, state, reason)
        self.mirror.end(run_id, RunState(state), reason)

    def _check_silent_runs(self) -> None:
        """A watched run silent for SILENT_RUN_CHECK_S is looked up: if the database says it
        ended (its final batch was lost with Redis), its viewers here are told."""
        now = time.monotonic()
        with self._lock:
            silent = [r for r, t in self._last_heard.items() if now - t > SILENT_RUN_CHECK_S]
        if not silent:
            return
        with self.store.session() as db:
            ends = {}
            for run_id in silent:
                record = run_store.get(db, run_id)
                if record is None or RunState(record.state).is_end:
                    ends[run_id] = (record.state, record.reason) if record else ("failed", "")
        for run_id, (state, reason) in ends.items():
            with self._lock:
                self._last_heard.pop(run_id, None)
            self.live.forget(run_id)
            self.mirror.end(run_id, RunState(state), reason)

    def _check_lost_queue(self) -> None:
        """Queued runs whose job Redis no longer holds (it restarted without its data) fail with
        a sentence instead of waiting forever. A worker removes the mark when it claims one."""
        cutoff = time.time() - QUEUE_LOST_AFTER_S
        with self.store.session() as db:
            waiting = run_store.queued_before(db, cutoff)
        if not waiting:
            return
        marks = self.client.exists(*[queued_key(r) for r in waiting]) if waiting else 0
        if marks == len(waiting):
            return
        for run_id in waiting:
            if self.client.exists(queued_key(run_id)):
                continue
            with self.store.session() as db:
                if run_store.end_if_active(db, run_id, str(RunState.FAILED), QUEUE_LOST):
                    log.warning("run %s: its job was lost with Redis; the run failed", run_id)
