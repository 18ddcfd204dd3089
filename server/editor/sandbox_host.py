"""The server's side of the editor's analysis host (host.py): start it inside its walls
(sandbox/editor_walls.py; in a cgroup of its own where the machine has cgroups), send it jobs,
hand each answer to the request waiting for it, and start another host when one dies or
stops answering. The message stubs the host reads are written once, before the first host.

    host = SandboxedHost(LIMITS, cache_dir); host.start()   # in the background: stubs, host
    job = host.submit(Op.COMPLETE, code, line=3, column=4)  # sent at once, or refused
    host.result(job)                                        # -> result dict, or
                                                            #    AnalysisUnavailable
    host.close()

With `sandboxed=False` (the lab's --unsafe-no-sandbox) the host is a plain child process: its
requests still limit and seal themselves, but it sees every file the server can; a DANGER line
is logged every time one starts.
"""

from __future__ import annotations

import collections
import contextlib
import dataclasses
import itertools
import json
import logging
import os
import select
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from concurrent.futures import Future
from concurrent.futures import TimeoutError as FutureTimeout
from pathlib import Path

import server.editor
from sandbox import bwrap, cgroups, editor_walls
from sandbox.limits import DEFAULT_LIMITS
from sandbox.protocol import FrameReader, FrameWriter, ProtocolError
from sandbox.seccomp import write_stage1_bpf
from server.editor.context import robot_catalog
from server.editor.frames import Answer, Cause, Job, Op, Ready, Refused, ToServer
from server.editor.limits import EditorLimits
from server.editor.ruff_tool import ruff_binary

log = logging.getLogger("robodojo.editor")
REPO_ROOT = Path(__file__).resolve().parents[2]
DANGER = (
    "DANGER: the editor's analysis runs WITHOUT a sandbox (--unsafe-no-sandbox): jedi and ruff "
    "read students' text with every file this server can read in reach"
)
STDERR_LINES = 40  # the host's last lines of output, logged when it fails to start
STDERR_LINE_BYTES = 2000  # [bytes] a longer line is cut


class AnalysisUnavailable(RuntimeError):
    """The analysis could not answer this request; the message is a sentence for the user.
    `cause`: what stopped the request in the host (its time, CPU or memory: the file is the
    reason), None when the host itself could not take it (starting, stopped, turned off)."""

    def __init__(self, message: str, cause: Cause | None = None) -> None:
        super().__init__(message)
        self.cause = cause


@dataclasses.dataclass
class _Running:
    """One host process and the jobs it has not answered yet."""

    process: subprocess.Popen
    writer: FrameWriter
    cgroup: cgroups.NodeCgroup | None
    ready: threading.Event = dataclasses.field(default_factory=threading.Event)
    pending: dict[int, Future] = dataclasses.field(default_factory=dict)
    lock: threading.Lock = dataclasses.field(default_factory=threading.Lock)
    stderr: collections.deque = dataclasses.field(
        default_factory=lambda: collections.deque(maxlen=STDERR_LINES)
    )
    ended: bool = False


@dataclasses.dataclass(frozen=True)
class Pending:
    """A job sent to a host, its answer to come (`SandboxedHost.result`)."""

    future: Future
    host: _Running | None = None  # None: answered already (refused before it was sent)
    budget_s: float = 0.0  # [s] the job's own budget, which the host enforces


class SandboxedHost:
    def __init__(
        self, limits: EditorLimits, cache_dir: Path | None = None, sandboxed: bool = True
    ) -> None:
        """`cache_dir`: where jedi keeps parsed modules across hosts (and server restarts);
        None: a folder that goes with this object."""
        self.limits = limits
        self.sandboxed = sandboxed
        self.cache_dir = cache_dir
        self.stub_root: Path | None = None
        self.ready = threading.Event()  # a host has taken jobs once: later waits are short
        self._running: _Running | None = None
        self._closed = False
        self._ids = itertools.count(1)
        self._lock = threading.Lock()
        self._failed_starts = 0
        self._groups = None
        self.problem: str | None = None  # why no host can start here, for every request

    # ----------------------------------------------------------------------------- life
    def start(self) -> None:
        threading.Thread(target=self._start, name="editor-host", daemon=True).start()

    def _start(self) -> None:
        try:
            if self.sandboxed:
                problem = bwrap.probe()
                if problem:
                    self.problem = (
                        f"the editor's analysis cannot run in a sandbox on this lab ({problem});"
                        " its operator can install bubblewrap"
                    )
                    log.error("%s", self.problem)
                    return
                self._groups = _memory_and_pids(cgroups.detect())
            # In a process of its own: building every message class holds the GIL for seconds,
            # which the server's event loop, starting at the same time, should not wait for.
            root = Path(tempfile.mkdtemp(prefix="robodojo-editor-"))
            subprocess.run(
                [sys.executable, "-m", "server.editor.stubs", str(root)],
                cwd=REPO_ROOT,
                check=True,
                capture_output=True,
                timeout=self.limits.host_start_timeout_s,
            )
            (root / "project").mkdir()  # the unsandboxed host's empty project folder
            self.stub_root = root
            if self.cache_dir is None:
                self.cache_dir = root / "jedi-cache"
            self.cache_dir.mkdir(parents=True, exist_ok=True)
            self._launch()
        except Exception:  # the editor's help is lost, the lab goes on; said in the log
            log.exception("the editor's analysis host did not start")

    def _launch(self) -> None:
        if self._closed:
            return
        try:
            (argv, fds), env, cwd, group = self._command()
        except OSError:  # a cgroup that cannot be made, a full disk: tried again later
            log.exception("the editor's analysis host could not be prepared")
            self._failed_starts += 1
            self._launch_later()
            return
        if not self.sandboxed:
            log.warning(DANGER)
        try:
            process = subprocess.Popen(
                argv,
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.PIPE,
                pass_fds=fds,
                env=env,
                cwd=cwd,
            )
        finally:
            for fd in fds:
                os.close(fd)
        running = _Running(process, FrameWriter(process.stdin.fileno()), group)
        with self._lock:
            self._running = running
        threading.Thread(target=self._drain_stderr, args=(running,), daemon=True,
                         name="editor-host-log").start()  # fmt: skip
        threading.Thread(target=self._read_answers, args=(running,), daemon=True,
                         name="editor-host-answers").start()  # fmt: skip

    def _launch_later(self) -> None:
        # Each failed start waits twice as long (at most 5 minutes): a broken install must not
        # start a process every few seconds forever.
        failures = self._failed_starts
        delay_s = min(5.0 * 2 ** (failures - 1), 300.0) if failures else 0.0
        timer = threading.Timer(delay_s, self._launch)
        timer.daemon = True
        timer.start()

    def _command(self) -> tuple[tuple[list[str], tuple[int, ...]], dict, str, object]:
        """((argv, fds to pass), environment, working folder, cgroup) of a new host."""
        assert self.stub_root is not None and self.cache_dir is not None
        limits = dataclasses.asdict(self.limits)
        if not self.sandboxed:
            settings = {
                "stub_root": str(self.stub_root),
                "cache_dir": str(self.cache_dir),
                "project_dir": str(self.stub_root / "project"),
                "library_root": str(self.stub_root / "common"),
                "ruff": ruff_binary(),
                "learn_roots": [str(self.stub_root), *editor_walls.library_roots(inside=False)],
                "robots": robot_catalog(),
                "limits": limits,
            }
            program = editor_walls.python_program("server.editor.host", [str(REPO_ROOT)])
            env = bwrap.node_environment(str(self.stub_root / "project"))
            return ([*program, json.dumps(settings)], ()), env, str(self.stub_root), None
        settings = {
            "stub_root": editor_walls.STUB_DIR,
            "cache_dir": editor_walls.CACHE_DIR,
            "project_dir": editor_walls.PROJECT_DIR,
            "library_root": editor_walls.LIBRARY_ROOT,
            "ruff": editor_walls.RUFF,
            "learn_roots": [editor_walls.STUB_DIR, *editor_walls.library_roots(inside=True)],
            "robots": robot_catalog(),
            "limits": limits,
        }
        with tempfile.TemporaryFile() as bpf:
            write_stage1_bpf(bpf)
            bpf.seek(0)
            seccomp_fd = os.dup(bpf.fileno())
        roots = [editor_walls.EDITOR_ROOT, editor_walls.LIBRARY_ROOT]
        program = editor_walls.python_program("server.editor.host", roots)
        command = editor_walls.build_command(
            seccomp_fd,
            str(Path(server.editor.__file__).resolve().parent),
            str(self.stub_root),
            str(self.cache_dir),
            os.path.realpath(ruff_binary()),
            [*program, json.dumps(settings)],
        )
        group = None
        if self._groups is not None:
            group = self._groups.create(
                dataclasses.replace(
                    DEFAULT_LIMITS,
                    memory_bytes=self.limits.sandbox_memory_bytes,
                    max_pids=self.limits.sandbox_pids,
                )
            )
            command = cgroups.enter_and_exec(group, command)
        # bwrap (pid 1 inside) starts with the sandbox's own environment, in "/": nothing of
        # the server's environment or working folder goes in (sandbox/bwrap.py says why).
        return (command, (seccomp_fd,)), bwrap.sandbox_environment(), "/", group

    def _drain_stderr(self, running: _Running) -> None:
        stream = running.process.stderr
        with stream:
            for line in iter(lambda: stream.readline(STDERR_LINE_BYTES), b""):
                text = line.decode(errors="replace").rstrip()
                running.stderr.append(text)
                log.debug("editor host: %s", text)

    def _read_answers(self, running: _Running) -> None:
        fd = running.process.stdout.fileno()
        reader = FrameReader(fd, ToServer)
        try:
            ready, _, _ = select.select([fd], [], [], self.limits.host_start_timeout_s)
            frame = reader.receive() if ready else None
            if not isinstance(frame, Ready):
                raise ProtocolError("no Ready from the host")
            log.info("the editor's analysis host is ready (%.1f s)", frame.startup_s)
            self._failed_starts = 0
            running.ready.set()
            self.ready.set()
            while True:
                frame = reader.receive()
                if isinstance(frame, Answer | Refused):
                    with running.lock:
                        future = running.pending.pop(frame.id, None)
                    if future is not None and not future.done():
                        future.set_result(frame)
        except (ProtocolError, OSError, ValueError):
            pass
        self._ended(running)

    def _ended(self, running: _Running) -> None:
        """The host is gone (or was made to go): fail what it owed, start another."""
        with running.lock:
            if running.ended:
                return
            running.ended = True
            pending, running.pending = list(running.pending.values()), {}
        _kill(running.process)
        if running.cgroup is not None:
            running.cgroup.remove()
        for future in pending:
            if not future.done():
                future.set_exception(AnalysisUnavailable(
                    "the editor's analysis stopped (its sandbox ended); it answers again in a "
                    "moment"))  # fmt: skip
        with self._lock:
            if self._running is running:
                self._running = None
        if self._closed:
            return
        if not running.ready.is_set():
            self._failed_starts += 1
            log.warning("the editor's analysis host did not start; its last lines: %s",
                        " | ".join(running.stderr) or "(none)")  # fmt: skip
        self._launch_later()

    # ----------------------------------------------------------------------------- jobs
    def submit(self, op: Op, code: str, **job: object) -> Pending:
        """Send a job to the host (waiting for a starting one a little); its answer comes
        through `result`."""
        refused: Future = Future()
        if self.limits.concurrent_requests == 0 or self.problem:
            refused.set_exception(AnalysisUnavailable(
                self.problem or "the editor's analysis is turned off on this lab"))  # fmt: skip
            return Pending(refused)
        wait_s = (self.limits.queue_wait_s if self.ready.is_set()
                  else self.limits.first_analysis_timeout_s)  # fmt: skip
        deadline = time.monotonic() + wait_s
        running = self._running
        while running is None or not running.ready.is_set():
            if time.monotonic() >= deadline or self._closed:
                starting = "" if self.ready.is_set() else " (it is still starting)"
                refused.set_exception(AnalysisUnavailable(
                    f"the editor's analysis is not running{starting}; it answers again in a "
                    "moment"))  # fmt: skip
                return Pending(refused)
            if running is not None:
                running.ready.wait(min(0.5, max(0.0, deadline - time.monotonic())))
            else:
                time.sleep(0.05)
            running = self._running
        frame = Job(id=next(self._ids), op=op, code=code, **job)
        future: Future = Future()
        with running.lock:
            if running.ended:
                future.set_exception(AnalysisUnavailable(
                    "the editor's analysis stopped; it answers again in a moment"))  # fmt: skip
                return Pending(future)
            running.pending[frame.id] = future
            with contextlib.suppress(OSError):  # the host is gone: its reader fails the job
                running.writer.send(frame)
        return Pending(future, running, self.limits.budget_s(op))

    def result(self, pending: Pending) -> dict:
        """The job's result dict; AnalysisUnavailable with a sentence if there is none."""
        timeout_s = pending.budget_s + self.limits.host_grace_s
        try:
            frame = pending.future.result(timeout=timeout_s if pending.host else 0)
        except FutureTimeout:
            log.error("the editor's analysis host gave no answer in %g s: replaced", timeout_s)
            self._ended(pending.host)
            raise AnalysisUnavailable(
                "the editor's analysis did not answer; it answers again in a moment"
            ) from None
        if isinstance(frame, Refused):
            raise AnalysisUnavailable(frame.reason, frame.cause)
        return frame.result

    def close(self) -> None:
        self._closed = True
        running = self._running
        if running is not None:
            with contextlib.suppress(OSError):
                running.process.stdin.close()
            self._ended(running)
        if self.stub_root is not None:
            shutil.rmtree(self.stub_root, ignore_errors=True)

    @property
    def process(self) -> subprocess.Popen | None:
        """The running host's process (bwrap's, when sandboxed), for the tests."""
        running = self._running
        return running.process if running is not None else None


def _memory_and_pids(groups):
    """The machine's cgroups without the cpu controller (v1), where it can be left out: in a
    cpu group of its own, the sandbox's processes all together weighed as much as one process
    of the machine's, and a completion took 2-3 times as long on a loaded machine. Its CPU is
    capped per request (RLIMIT_CPU), and one request at a time per student (limits.py)."""
    if isinstance(groups, cgroups.Cgroups):
        return cgroups.Cgroups({c: d for c, d in groups.bases.items() if c != "cpu"})
    return groups  # cgroup v2: a child group has every controller its parent enables


def _kill(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.kill()
    with contextlib.suppress(subprocess.TimeoutExpired):
        process.wait(timeout=5.0)
    for stream in (process.stdin, process.stdout):
        with contextlib.suppress(OSError):
            if stream is not None:
                stream.close()
