"""The embedded lab's default executor (issue 16): one worker process per core on this machine,
started and watched by the web process, no Redis. Twenty realtime runs in one interpreter miss
their periods (bench/bench_runs.py); spread over processes, each core keeps its own.

    executor = LocalProcessExecutor(store, settings, launcher, hardware, processes=4)
    executor.submit(job)           # to the least loaded process with room

Each child (server/workers/local_worker.py) is made by a forkserver (the web process has
threads: a plain fork could copy a held lock) and holds its own Store, Launcher and RunHost; the
parent reads each child's pipe on a thread of its own and applies the batches to its Mirrors. A
child that dies (SIGKILL, a crash) is seen at once on its pipe: its runs end "failed: worker
lost" in the database and, live, in their mirrors; it is started again. Runs on a real robot stay
in this process (an InProcessExecutor): the robots' connections are held here.
"""

from __future__ import annotations

import contextlib
import logging
import math
import multiprocessing
import os
import signal
import socket
import threading
import time
import uuid
from dataclasses import dataclass, field
from multiprocessing.connection import Connection

from sandbox.launcher import Launcher
from server.runs.commands import CommandError, RunCommand
from server.runs.state import RunState
from server.service.telemetry import RunTelemetry
from server.store import runs as run_store
from server.store.db import Store
from server.workers.inprocess import InProcessExecutor
from server.workers.local_worker import child_main
from server.workers.mirror import Mirrors
from server.workers.seams import ExecutorUnavailableError
from server.workers.wire import (
    CommandAnswer,
    CommandRequest,
    LiveBatch,
    RunJob,
    RunStatus,
    WireError,
    answer_from_json,
    batch_from_json,
    dumps,
    job_to_json,
    loads,
    request_to_json,
)

log = logging.getLogger("robodojo.workers")

COMMAND_TIMEOUT_S = 5.0  # [s] a command's answer from a child; a child this slow is in trouble
READY_TIMEOUT_S = 60.0  # [s] a child's start (imports, database, warm sandboxes) on a busy host
RESTART_PAUSE_S = 1.0  # [s] before a lost child is started again: no tight crash loop
WORKER_LOST = "failed: worker lost (its worker process ended unexpectedly); start the run again"


@dataclass
class _Child:
    index: int
    process: multiprocessing.process.BaseProcess
    conn: Connection
    capacity: int
    worker_id: str = ""
    warm: int = 0  # warm sandboxes waiting in the child, as it last said
    runs: set[str] = field(default_factory=set)
    ready: threading.Event = field(default_factory=threading.Event)
    closed: threading.Event = field(default_factory=threading.Event)
    ended: threading.Event = field(default_factory=threading.Event)  # its pipe ended, runs told
    alive: bool = True
    send_lock: threading.Lock = field(default_factory=threading.Lock)
    started_s: float = field(default_factory=time.monotonic)


def _kill_group(pid: int | None) -> None:
    """Kill what is left of an ended child's process group (local_worker.child_main makes it):
    its sandboxes. bwrap's --die-with-parent ends a sandbox whose worker died, but not one still
    starting when it died, nor an unsandboxed node (--unsafe-no-sandbox), which would otherwise
    run on with nobody reading its pipes. The group's id stays taken while any member lives, so
    this cannot reach a stranger's group unless the group is empty and the pid already reused."""
    if pid is None:
        return
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(pid, signal.SIGKILL)


class _Waiter:
    """A command's answer to come."""

    def __init__(self, child: _Child) -> None:
        self.child = child
        self.done = threading.Event()
        self.answer: CommandAnswer | None = None


class LocalProcessExecutor:
    """A RunExecutor over worker processes of this machine (see the module doc)."""

    def __init__(
        self,
        store: Store,
        settings,
        launcher: Launcher,
        hardware=None,
        processes: int | None = None,
    ) -> None:
        self.store = store
        self.settings = settings
        self.count = max(1, processes or 1)
        self.capacity = math.ceil(settings.max_runs_total / self.count)  # per child
        self.mirrors = Mirrors()
        # Real robots' runs, here where their connections are.
        self.local = InProcessExecutor(
            store, settings, launcher, hardware, mirrors=self.mirrors, robots_only=True
        )
        self._context = multiprocessing.get_context("forkserver")
        self._context.set_forkserver_preload(["server.workers.local_worker"])
        self._lock = threading.Lock()
        self._children: list[_Child | None] = [None] * self.count
        self._where: dict[str, _Child] = {}  # run id -> the child holding it
        self._waiters: dict[str, _Waiter] = {}  # command request id -> its waiter
        self._closing = False
        for index in range(self.count):
            self._start_child(index)

    # ------------------------------------------------------------------------------ children
    def _start_child(self, index: int) -> _Child:
        parent_end, child_end = self._context.Pipe(duplex=True)
        process = self._context.Process(
            target=child_main,
            args=(self.settings, child_end, index),
            name=f"robodojo-worker-{index}",
            daemon=True,
        )
        process.start()
        child_end.close()  # the child's death must read as the end of this pipe here
        child = _Child(index, process, parent_end, self.capacity)
        with self._lock:
            self._children[index] = child
        threading.Thread(
            target=self._read, args=(child,), name=f"worker-{index}-reader", daemon=True
        ).start()
        return child

    def wait_ready(self, timeout_s: float = READY_TIMEOUT_S, warm: bool = False) -> bool:
        """Whether every child said it is ready (and, with `warm`, has its whole pool of warm
        sandboxes) within `timeout_s` (tests, benches)."""
        deadline = time.monotonic() + timeout_s
        for child in self._live_children():
            if not child.ready.wait(max(0.0, deadline - time.monotonic())):
                return False
            while warm and child.warm < self.settings.sandbox_pool:
                if time.monotonic() > deadline:
                    return False
                time.sleep(0.05)
        return True

    def warm_count(self) -> int:
        """Warm sandboxes waiting in every worker process."""
        return sum(child.warm for child in self._live_children())

    def _live_children(self) -> list[_Child]:
        with self._lock:
            return [child for child in self._children if child is not None and child.alive]

    def _read(self, child: _Child) -> None:
        """The child's pipe, until it ends: batches into the mirrors, answers to waiters.

        The pipe's end is the child's end: nobody else holds its side (the forkserver closes
        its copy once it has forked). Not the process's sentinel: that is a pipe from the
        forkserver, which reads as "exit code 255" when the forkserver itself is killed (a
        service manager's SIGTERM to the whole group) while the child still runs its runs."""
        while True:
            try:
                raw = child.conn.recv_bytes()
            except (EOFError, OSError):
                break
            try:
                self._on_message(child, loads(raw))
            except (WireError, ValueError, TypeError, KeyError) as error:
                log.error("worker process %d sent what cannot be read: %s", child.index, error)
        self._lost(child)

    def _on_message(self, child: _Child, message: dict) -> None:
        op = message.get("op")
        if op == "batches":  # one publisher round of the child's runs
            for data in message["batches"]:
                try:
                    batch = batch_from_json(data)
                except WireError as error:  # one bad batch; the round's others still count
                    log.error("worker process %d sent a bad live batch: %s", child.index, error)
                    continue
                self._on_batch(child, batch)
        elif op == "answer":
            answer = answer_from_json(message["answer"])
            with self._lock:
                waiter = self._waiters.pop(answer.request_id, None)
            if waiter is not None:
                waiter.answer = answer
                waiter.done.set()
        elif op == "ready":
            child.worker_id = str(message.get("worker", ""))
            child.ready.set()
        elif op == "warm":
            child.warm = int(message.get("count", 0))
        elif op == "closed":
            child.closed.set()

    def _on_batch(self, child: _Child, batch: LiveBatch) -> None:
        self.mirrors.apply(batch)
        if batch.final:
            with self._lock:
                child.runs.discard(batch.run_id)
                if self._where.get(batch.run_id) is child:
                    del self._where[batch.run_id]

    def _lost(self, child: _Child) -> None:
        """The child ended: if it still held runs, they failed with it; start another."""
        _kill_group(child.process.pid)
        child.process.join(timeout=5.0)
        with self._lock:
            child.alive = False
            runs = sorted(child.runs)
            child.runs.clear()
            for run_id in runs:
                self._where.pop(run_id, None)
            waiters = [w for w in self._waiters.values() if w.child is child]
            for waiter in waiters:
                waiter.done.set()  # no answer: the run is not running any more
            closing = self._closing
        child.conn.close()
        if runs or not closing:
            log.error(
                "worker process %d (%s) ended with exit code %s, holding %d run(s)",
                child.index, child.worker_id, child.process.exitcode, len(runs),
            )  # fmt: skip
        for run_id in runs:
            try:
                with self.store.session() as db:
                    run_store.end_if_active(db, run_id, str(RunState.FAILED), WORKER_LOST)
            except Exception:  # the mirror still tells the viewers; the record is fixed later
                log.exception("run %s: could not store that its worker was lost", run_id)
            self.mirrors.end(run_id, RunState.FAILED, WORKER_LOST)
        child.ended.set()
        if closing:
            return
        if time.monotonic() - child.started_s < RESTART_PAUSE_S:
            time.sleep(RESTART_PAUSE_S)
        with self._lock:
            if self._closing:
                return
        try:
            self._start_child(child.index)
        except Exception as error:  # the machine is going down, or out of processes
            log.error(
                "worker process %d could not be started again (%s); new runs go to the others",
                child.index, error,
            )  # fmt: skip

    def _send(self, child: _Child, message: dict) -> None:
        with child.send_lock:
            child.conn.send_bytes(dumps(message))

    # ------------------------------------------------------------------------------ executor
    def submit(self, job: RunJob) -> None:
        if job.hardware is not None:
            self.local.submit(job)  # its robot's connection is in this process
            return
        with self._lock:
            if self._closing:
                raise ExecutorUnavailableError("the server is shutting down; try again in a minute")
            candidates = [
                c
                for c in self._children
                if c is not None and c.alive and len(c.runs) < c.capacity  # ready or not:
                # a child still starting reads its pipe once it is
            ]
            if not candidates:
                raise ExecutorUnavailableError(
                    "every worker process of this lab is busy or starting; try again in a few "
                    "seconds"
                )
            child = min(candidates, key=lambda c: len(c.runs))
            child.runs.add(job.run_id)
            self._where[job.run_id] = child
        self.mirrors.expect(job.run_id)
        try:
            self._send(child, {"op": "job", "job": job_to_json(job)})
        except (OSError, ValueError) as error:
            with self._lock:
                child.runs.discard(job.run_id)
                self._where.pop(job.run_id, None)
            self.mirrors.end(job.run_id, RunState.FAILED, WORKER_LOST)
            raise ExecutorUnavailableError(
                f"the worker process could not take the run ({error}); try again in a few seconds"
            ) from None

    def command(self, run_id: str, command: RunCommand) -> bool:
        with self._lock:
            child = self._where.get(run_id)
            if child is None:
                local = True
            else:
                local = False
                request = CommandRequest(uuid.uuid4().hex, run_id, command)
                waiter = self._waiters[request.request_id] = _Waiter(child)
        if local:
            return self.local.command(run_id, command)
        try:
            self._send(child, {"op": "command", "request": request_to_json(request)})
            answered = waiter.done.wait(COMMAND_TIMEOUT_S)
        except (OSError, ValueError):
            answered = True  # the child is gone: the run is not running any more
        finally:
            with self._lock:
                self._waiters.pop(request.request_id, None)
        if not answered:
            raise CommandError(
                f"the worker process running this run did not answer within "
                f"{COMMAND_TIMEOUT_S:g} s; try again"
            )
        answer = waiter.answer
        if answer is None:
            return False
        if answer.refusal is not None:
            raise CommandError(answer.refusal)
        return answer.taken

    def status(self, run_id: str) -> RunStatus | None:
        if run_id in self._where:
            return self.mirrors.status(run_id)
        return self.local.status(run_id)

    def feed(self, run_id: str) -> RunTelemetry | None:
        return self.mirrors.feed(run_id)

    def is_running(self, run_id: str) -> bool:
        return self.mirrors.is_running(run_id)

    def running(self) -> list[str]:
        return self.mirrors.running()

    def children_pids(self) -> list[int]:
        """The worker processes' pids, in order (tests kill one)."""
        return [child.process.pid for child in self._live_children()]

    def runs_of(self, pid: int) -> list[str]:
        """The runs held by the worker process `pid` (tests)."""
        with self._lock:
            return sorted(
                run_id for run_id, child in self._where.items() if child.process.pid == pid
            )

    def workers(self) -> list[dict]:
        host = socket.gethostname()
        rows = [
            {
                "id": child.worker_id or f"{host}:{child.process.pid}",
                "host": host,
                "role": "worker process",
                "capacity": child.capacity,
                "running": len(child.runs),
                "warm": child.warm,
                "state": "up" if child.ready.is_set() else "starting",
                "last_seen_s": 0.0,
            }
            for child in self._live_children()
        ]
        return [*rows, *self.local.workers()]

    def shutdown(self, grace_s: float) -> None:
        """Stop every run (robots to zero as each ends) within `grace_s`; end the children."""
        with self._lock:
            self._closing = True
        children = self._live_children()
        for child in children:
            with contextlib.suppress(OSError, ValueError):
                self._send(child, {"op": "close", "grace_s": grace_s})
        self.local.shutdown(grace_s)
        deadline = time.monotonic() + grace_s + 2.0
        for child in children:
            # Its pipe, not the process's sentinel, says it ended (see _read); while the pipe is
            # open the child exists, so its pid is still its own to kill.
            if not child.ended.wait(max(0.1, deadline - time.monotonic())):
                log.error("worker process %d did not end in time; killed", child.index)
                _kill_group(child.process.pid)
                child.ended.wait(5.0)
