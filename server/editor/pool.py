"""The server's side of the analysis workers (worker.py): a few child processes, each answering
one request at a time. A request that outlives its time limit, or a worker that dies, costs
that worker (killed and replaced in the background), never the server and never the next
request. The message stubs the workers read are written once, when the pool starts.

    pool = AnalysisPool(); pool.start()        # in the background: stubs, workers, warm-up
    pool.call({"op": "complete", ...})         # -> result dict, or AnalysisUnavailable
    pool.close()
"""

from __future__ import annotations

import json
import logging
import queue
import selectors
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from server.editor.limits import LIMITS, EditorLimits

log = logging.getLogger("robodojo.editor")
REPO_ROOT = Path(__file__).resolve().parents[2]
# Looked at by a new worker before it takes requests, when another worker already does: the
# other libraries a node's warm process imports (sandbox/runner.py). jedi's first look at
# matplotlib.pyplot or scipy.signal takes 5-10 s on a loaded machine; the worker keeps what it
# learnt and jedi's disk cache shares the parsing with the others.
WARM_LATER = (
    ("import matplotlib.pyplot as plt\nplt.", 2, 4),
    ("import scipy.signal\nscipy.signal.", 2, 13),
    ("import skfuzzy as fuzz\nfuzz.", 2, 5),
    ("import math, random, time\nmath.", 2, 5),
)


class AnalysisUnavailable(RuntimeError):
    """The analysis could not answer this request; the message is a sentence for the user."""


class Worker:
    def __init__(self, stub_root: Path, cache_dir: Path) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-m", "server.editor.worker", str(stub_root), str(cache_dir)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            cwd=REPO_ROOT,
        )
        self.requests = 0
        self._buffer = b""

    def read_line(self, timeout_s: float) -> dict:
        """The next JSON line, or TimeoutError / EOFError."""
        stdout = self.process.stdout
        assert stdout is not None
        deadline = time.monotonic() + timeout_s
        with selectors.DefaultSelector() as selector:
            selector.register(stdout, selectors.EVENT_READ)
            while b"\n" not in self._buffer:
                left = deadline - time.monotonic()
                if left <= 0 or not selector.select(left):
                    raise TimeoutError
                chunk = stdout.read1(1 << 20)
                if not chunk:
                    raise EOFError
                self._buffer += chunk
        line, self._buffer = self._buffer.split(b"\n", 1)
        return json.loads(line)

    def ask(self, request: dict, timeout_s: float) -> dict:
        assert self.process.stdin is not None
        self.process.stdin.write(json.dumps(request).encode() + b"\n")
        self.process.stdin.flush()
        self.requests += 1
        return self.read_line(timeout_s)

    def kill(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
        self.process.wait()
        for stream in (self.process.stdin, self.process.stdout):
            try:
                if stream is not None:
                    stream.close()
            except OSError:
                pass


class AnalysisPool:
    def __init__(self, limits: EditorLimits = LIMITS, cache_dir: Path | None = None) -> None:
        """`cache_dir`: where jedi keeps parsed modules across workers (and server restarts);
        None: a folder that goes with the pool."""
        self.limits = limits
        self.cache_dir = cache_dir
        self.idle: queue.Queue[Worker] = queue.Queue()
        self.stub_root: Path | None = None
        self.ready = threading.Event()
        self._closed = False
        self._lock = threading.Lock()
        self._workers: set[Worker] = set()
        self._failed_starts = 0

    def start(self) -> None:
        threading.Thread(target=self._start, name="editor-pool", daemon=True).start()

    def _start(self) -> None:
        try:
            # In a process of its own: building every message class holds the GIL for seconds,
            # which the server's event loop, starting at the same time, should not wait for.
            root = Path(tempfile.mkdtemp(prefix="robodojo-editor-"))
            subprocess.run(
                [sys.executable, "-m", "server.editor.stubs", str(root)],
                cwd=REPO_ROOT,
                check=True,
                capture_output=True,
                timeout=self.limits.worker_start_timeout_s,
            )
            self.stub_root = root
            for _ in range(self.limits.workers):
                self._spawn()
        except Exception:  # the editor's help is lost, the lab goes on; said in the log
            log.exception("the editor's analysis workers did not start")

    def _spawn(self) -> None:
        """Start a worker and wait until it has warmed up; then it takes requests."""
        if self._closed or self.stub_root is None:
            return
        worker = Worker(self.stub_root, self.cache_dir or self.stub_root / "jedi-cache")
        with self._lock:
            self._workers.add(worker)
        try:
            hello = worker.read_line(self.limits.worker_start_timeout_s)
            if not hello.get("ready"):
                raise EOFError
        except (TimeoutError, EOFError, ValueError):
            self._retire(worker)
            self._failed_starts += 1
            if not self._closed:
                # Each failure waits twice as long (at most 5 minutes): a broken install
                # must not spin up a process every few seconds forever.
                delay_s = min(5.0 * 2 ** (self._failed_starts - 1), 300.0)
                log.warning("an editor analysis worker did not start; trying again in %g s",
                            delay_s)  # fmt: skip
                timer = threading.Timer(delay_s, self._spawn)
                timer.daemon = True
                timer.start()
            return
        self._failed_starts = 0
        others_answer = not self.idle.empty()
        if others_answer and not self._warm_later(worker):
            self._replace(worker)
            return
        self.idle.put(worker)
        self.ready.set()

    def _warm_later(self, worker: Worker) -> bool:
        """False if the worker did not answer (it is then replaced: an answer still to come
        would be taken for the next request's)."""
        for code, line, column in WARM_LATER:
            request = {"op": "complete", "code": code, "line": line, "column": column}
            try:
                worker.ask(request, self.limits.analysis_hard_timeout_s)
            except (TimeoutError, EOFError, OSError, ValueError):
                return False
        return True

    def _retire(self, worker: Worker) -> None:
        worker.kill()
        with self._lock:
            self._workers.discard(worker)

    def _replace(self, worker: Worker) -> None:
        self._retire(worker)
        if self._closed:
            return
        threading.Thread(target=self._spawn, name="editor-worker", daemon=True).start()

    def _finish(self, worker: Worker) -> None:
        """A worker past the caller's time limit: back to work once it answers (its answer
        is dropped), killed and replaced if it has not by the hard limit."""
        left_s = self.limits.analysis_hard_timeout_s - self.limits.analysis_timeout_s
        try:
            worker.read_line(max(left_s, 0.0))
        except (TimeoutError, EOFError, OSError, ValueError):
            log.warning("an editor analysis worker passed %g s on one request: replaced",
                        self.limits.analysis_hard_timeout_s)  # fmt: skip
            self._replace(worker)
            return
        self._release(worker)

    def _release(self, worker: Worker) -> None:
        if worker.requests >= self.limits.worker_max_requests or self._closed:
            self._replace(worker)
        else:
            self.idle.put(worker)

    def call(self, request: dict) -> dict:
        """The worker's result for `request`; AnalysisUnavailable with a sentence if none."""
        limits = self.limits
        wait_s = limits.queue_wait_s if self.ready.is_set() else limits.first_analysis_timeout_s
        if limits.workers == 0:
            raise AnalysisUnavailable("the editor's analysis is turned off on this lab")
        try:
            worker = self.idle.get(timeout=wait_s)
        except queue.Empty:
            starting = "" if self.ready.is_set() else " (it is still starting)"
            raise AnalysisUnavailable(
                f"the editor's analysis is busy{starting}; it answers again in a moment"
            ) from None
        try:
            answer = worker.ask(request, self.limits.analysis_timeout_s)
        except TimeoutError:
            threading.Thread(target=self._finish, args=(worker,), daemon=True).start()
            raise AnalysisUnavailable(
                f"the analysis of this file took longer than {self.limits.analysis_timeout_s:g} "
                "s; it answers faster once it has read the modules this file imports (very long "
                "or deeply nested code can also cause this)"
            ) from None
        except (EOFError, OSError, ValueError):
            self._replace(worker)
            raise AnalysisUnavailable(
                "the analysis stopped on this file (its worker ended); very long or deeply "
                "nested code can cause this"
            ) from None
        self._release(worker)
        if not answer.get("ok"):
            raise AnalysisUnavailable(answer.get("error", "the analysis failed"))
        return answer["result"]

    def close(self) -> None:
        self._closed = True
        with self._lock:
            workers = list(self._workers)
        for worker in workers:
            self._retire(worker)
        if self.stub_root is not None:
            shutil.rmtree(self.stub_root, ignore_errors=True)
