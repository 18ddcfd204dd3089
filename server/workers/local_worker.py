"""One worker process of the embedded lab (issue 16): started by the web process's
LocalProcessExecutor (server/workers/processes.py) with a spawn-like context, it opens its own
Store and Launcher, holds a RunHost, and talks to its parent over one duplex pipe of JSON
messages (server/workers/wire.py codecs; never pickle):

    parent -> child   {"op": "job", "job": ...}        {"op": "command", "request": ...}
                      {"op": "close", "grace_s": s}
    child -> parent   {"op": "ready", "worker": id}    {"op": "batches", "batches": [...]}
                      {"op": "answer", "answer": ...}  {"op": "warm", "count": n}
                      {"op": "closed"}

The parent going away (the pipe's end) closes the child too: its runs are stopped, robots to zero.
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal
import threading
from collections.abc import Sequence
from multiprocessing.connection import Connection

from sandbox.launcher import Launcher
from server.runs.commands import CommandError
from server.sim.registry import topic_types
from server.store.db import Store
from server.workers.host import RunHost
from server.workers.wire import (
    CommandAnswer,
    LiveBatch,
    WireError,
    answer_to_json,
    batch_to_json,
    dumps,
    job_from_json,
    loads,
    request_from_json,
)

log = logging.getLogger("robodojo.workers")

WARM_REPORT_S = 0.5  # [s] how often the warm sandbox count is looked at (sent when it changed)


class PipeOutlet:
    """A LiveOutlet into the pipe to the web process."""

    def __init__(self, send) -> None:
        self._send = send

    def publish_round(self, batches: Sequence[LiveBatch]) -> None:
        """The round in one pipe message (one write, one wake of the web's reader). A batch
        JSON refuses (a NaN) is left out with a line in the log; the others still go."""
        encoded = [batch_to_json(batch) for batch in batches]
        try:
            try:
                self._send({"op": "batches", "batches": encoded})
            except ValueError:  # rare: find the bad batch and send the rest
                encoded = [data for data in encoded if _encodable(data)]
                if encoded:
                    self._send({"op": "batches", "batches": encoded})
        except OSError:  # the web process is gone; this worker is ending too
            log.warning("a round of %d live batches lost: the web process is gone", len(batches))


def _encodable(data: dict) -> bool:
    try:
        dumps(data)
    except ValueError as error:
        log.error("run %s: a live batch is not JSON and was dropped: %s", data["run_id"], error)
        return False
    return True


class LocalWorker:
    """The child's side: reads the pipe, runs jobs on threads of their own, answers commands."""

    def __init__(self, settings, conn: Connection, worker_id: str) -> None:
        self.settings = settings
        self.conn = conn
        self._send_lock = threading.Lock()
        self._closing = threading.Event()
        self.store = Store.open(settings.store_url)
        self.launcher = Launcher(
            pool_size=settings.sandbox_pool,
            unsafe_no_sandbox=settings.unsafe_no_sandbox,
            message_types=topic_types(),
        )
        self.host = RunHost(self.store, settings, self.launcher, PipeOutlet(self.send), worker_id)

    def send(self, message: dict) -> None:
        data = dumps(message)
        with self._send_lock:  # the publisher and the reader both send
            self.conn.send_bytes(data)

    def _report_warm(self) -> None:
        """Tell the parent how many warm sandboxes wait here whenever it changes (its status
        page; a bench waits for full pools)."""
        told = -1
        while not self._closing.wait(WARM_REPORT_S):
            count = self.launcher.warm_count
            if count != told:
                with contextlib.suppress(OSError, ValueError):
                    self.send({"op": "warm", "count": count})
                told = count

    def serve(self) -> None:
        grace_s = self.settings.shutdown_grace_s
        threading.Thread(target=self._report_warm, name="warm-report", daemon=True).start()
        try:
            self.send({"op": "ready", "worker": self.host.worker_id})
            while True:
                raw = self.conn.recv_bytes()
                try:
                    message = loads(raw)
                    op = message.get("op") if isinstance(message, dict) else None
                    if op == "close":
                        grace_s = float(message.get("grace_s", grace_s))
                        break
                    self._handle(op, message)
                except (WireError, ValueError, TypeError) as error:
                    log.error("worker %s: a message it cannot read: %s", self.host.worker_id, error)
        except (EOFError, OSError):  # the web process is gone: stop what runs here
            pass
        finally:
            self._closing.set()
            self.host.close(grace_s)
            self.launcher.close()
            self.store.close()
            with contextlib.suppress(OSError, ValueError):
                self.send({"op": "closed"})

    def _handle(self, op, message: dict) -> None:
        if op == "job":
            job = job_from_json(message.get("job"))
            if self.host.accept(job):  # before the next message: a command after it finds it
                threading.Thread(
                    target=self.host.execute,
                    args=(job,),
                    name=f"run-{job.run_id[:8]}",
                    daemon=True,  # past the shutdown grace, the process ends anyway
                ).start()
        elif op == "command":
            request = request_from_json(message.get("request"))
            try:
                taken = self.host.command(request.run_id, request.command)
                answer = CommandAnswer(request.request_id, taken)
            except CommandError as error:
                answer = CommandAnswer(request.request_id, False, refusal=str(error))
            self.send({"op": "answer", "answer": answer_to_json(answer)})
        else:
            raise WireError(f"unknown operation {op!r}")


def child_main(settings, conn: Connection, index: int) -> None:
    """The worker process's entry point (multiprocessing target)."""
    # Ctrl-C in a terminal, and a service manager's stop (systemd's default KillMode, `timeout`),
    # reach the whole process group: the web process stops the runs cleanly (it sends "close",
    # robots to zero), not a signal in the middle of this one's work. A worker whose web
    # process is gone still ends: its pipe closes.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    # A process group of its own, which its sandboxes join (bwrap itself; an unsandboxed node):
    # if this process is killed, the web process kills the group, so no node outlives it.
    os.setpgid(0, 0)
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    logging.getLogger("alembic").setLevel(logging.WARNING)  # the web process said it already
    worker_id = f"{os.uname().nodename}:{os.getpid()}"
    try:
        worker = LocalWorker(settings, conn, worker_id)
    except Exception:
        log.exception("worker process %d could not start", index)
        raise SystemExit(2) from None
    worker.serve()
