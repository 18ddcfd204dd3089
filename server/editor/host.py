"""The editor's analysis host: the one long-lived process inside the editor's sandbox
(sandbox/editor_walls.py says what it sees). It loads jedi, our checks and the stubs once,
warms jedi up on what nodes import, and then answers each Job in a process forked from it
(request.py):

- the process inherits the warm caches, limits itself (its own CPU seconds and address space)
  and seals itself (no file written, nothing started, no signal to others) before it reads a
  student's text; ruff's processes are forked by a small twin of the host (`main`);
- the host kills it when its job passes its time budget and answers Refused with a sentence,
  while the other requests go on; RLIMIT_CPU and RLIMIT_AS stop it from inside too;
- it writes only to its pipe: nothing of one student's request is left for another. An
  analysis process answers one student's jobs only, their next ones too for a while
  (`sessions`; request.py says why), and exits when let go; a ruff process answers one job.
  Spares, limited and sealed, are forked ahead, one of each kind per request the server may
  send at once.

What a request learns is not lost with it: the library modules jedi parsed for it are parsed
again in the host (learning.py), for the processes forked after.

A poll loop (and the learner's thread): jobs from the server (fd 0), answers from the
requests' pipes and the twin, deadlines. Started by server/editor/sandbox_host.py with its
settings, as JSON, for argument.
"""

from __future__ import annotations

import contextlib
import fcntl
import gc
import hashlib
import json
import math
import os
import resource
import select
import signal
import struct
import sys
import time
from collections import deque
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path

import msgspec

from sandbox.protocol import FrameReader, FrameWriter, ProtocolError
from server.editor import endings
from server.editor.frames import (
    RUFF_OPS,
    Answer,
    Cause,
    Done,
    FromRequest,
    Job,
    Op,
    Parsed,
    Ready,
    Refused,
    ToHost,
    ToServer,
)
from server.editor.learning import Learner, safe_parse_cache
from server.editor.limits import EditorLimits, MiB
from server.editor.request import analysis_process, ruff_process

# What the host analyses before it says it is ready: jedi's first look at rospy, rclpy, the
# message stubs and numpy costs seconds, matplotlib.pyplot and scipy.signal 5-10 s on a loaded
# machine (the libraries a node's warm process imports, sandbox/runner.py); a student's first
# request should not pay it, and every request inherits it ...
WARM_UP = (
    ("import rospy\nimport numpy as np\nfrom geometry_msgs.msg import Twist\n"
     "from sensor_msgs.msg import LaserScan\ncmd = Twist()\ncmd.linear.\nrospy.\nnp.\n",
     ((6, 11), (7, 6), (8, 3))),
    ("import rclpy\nfrom rclpy.node import Node\nfrom geometry_msgs.msg import Twist\n"
     "class N(Node):\n    def f(self):\n        self.\n        Twist().linear.\n",
     ((6, 13), (7, 23))),
    ("def step(obs):\n    obs.\n", ((2, 8),)),
)  # fmt: skip
# ... and, once it is ready, in request processes of its own whose parses it learns (so that
# requests are answered meanwhile): the other libraries a node's warm process imports.
WARM_LATER = (
    ("import matplotlib.pyplot as plt\nplt.", 2, 4),
    ("import scipy.signal\nscipy.signal.", 2, 13),
    ("import skfuzzy as fuzz\nfuzz.", 2, 5),
    ("import math, random, time\nmath.", 2, 5),
)
WARM_NICE = 19  # the warm-up processes' niceness: they use only what requests leave
WARM_CHECK = "from geometry_msgs.msg import Twist\ncmd = Twist()\ncmd.linear.x = 0.1\n"
READ_BYTES = 1 << 16  # [bytes] read from a request's pipe at a time
# A job pipe's size [bytes]: the largest job (a 256 KiB file, twice the bytes in the worst
# UTF-8) is written in one go, so the host never waits on a request. Linux's pipe-max-size
# for unprivileged processes is 1 MiB; a smaller one only makes the write wait for the read.
JOB_PIPE_BYTES = 1 * MiB
FRAME_LENGTH = struct.Struct("<I")  # sandbox/protocol.py's frames: little-endian length first
FROM_REQUEST = msgspec.msgpack.Decoder(FromRequest)


class Kind(StrEnum):
    ANALYSIS = "analysis"  # checks, completion, hover: request.analysis_process
    RUFF = "ruff"  # ruff check and format: request.ruff_process


@dataclass
class Child:
    """A request's process, as the host sees it: a spare until it has a job."""

    pid: int
    kind: Kind
    job_fd: int | None  # the host's end of its job pipe, until the job is written
    out_fd: int  # the analysis frames' pipe, or ruff's stdout
    err_fd: int | None = None  # ruff's stderr
    out: bytearray = field(default_factory=bytearray)
    err: bytearray = field(default_factory=bytearray)
    open_fds: set[int] = field(default_factory=set)
    job: Job | None = None
    budget_s: float = 0.0  # [s]
    deadline: float = math.inf  # [s] monotonic
    truncated: bool = False  # ruff said more than we take back
    answered: bool = False
    stale: bool = False  # let go: it exits when it sees its job pipe closed
    user: str | None = None  # the student whose jobs an analysis process answers
    served: int = 0  # jobs answered
    idle_since: float = 0.0  # [s] monotonic, for a student's process between their jobs


@dataclass
class RuffRunner:
    """The host's small twin that runs ruff (`main` says why), as the host sees it."""

    pid: int
    jobs: FrameWriter  # the host sends it ruff's jobs ...
    answers_fd: int  # ... and relays its answers to the server
    answers: FrameReader


class Host:
    def __init__(
        self, settings: dict, kinds: tuple[Kind, ...], ruff_runner: RuffRunner | None = None
    ) -> None:
        """`kinds`: the processes this host forks (ruff's go to `ruff_runner` when there is
        one)."""
        self.limits = EditorLimits(**settings["limits"])
        self.ruff = settings["ruff"]
        self.cache_dir = Path(settings["cache_dir"])
        self.learn_roots = tuple(os.path.realpath(p) for p in settings["learn_roots"])
        self.kinds = kinds
        self.ruff_runner = ruff_runner
        self.analyser = None
        if Kind.ANALYSIS in kinds:
            from server.editor.complete import Analyser
            from server.editor.context import install_robot_catalog

            install_robot_catalog(settings["robots"])
            safe_parse_cache()
            self.analyser = Analyser(
                Path(settings["stub_root"]),
                tuple(settings["robots"]),
                self.cache_dir,
                Path(settings["project_dir"]),
                Path(settings["library_root"]),
            )
        self.children: dict[int, Child] = {}  # by pid
        self.by_fd: dict[int, Child] = {}  # by each pipe the host reads
        self.sessions: dict[str, Child] = {}  # a student's analysis process, by user
        self.learner: Learner | None = None
        self.spare_failures: dict[Kind, int] = {}  # spares of a kind that died before a job
        self.spares_paused_until: dict[Kind, float] = {}  # [s] monotonic
        self.warm_later = deque(WARM_LATER if self.analyser else ())
        self.poller = select.poll()
        self.out: FrameWriter | None = None

    # ----------------------------------------------------------------------------- start
    def warm_up(self) -> None:
        from server.editor.api_checks import check
        from server.editor.syntax import parse

        for code, places in WARM_UP:
            for line, column in places:
                self.analyser.complete(code, line, column, "crowbot")
        check(WARM_CHECK, parse(WARM_CHECK).tree, "crowbot")
        state = self.analyser._script("", None, ())[0]._inference_state
        grammars = {g._hashed: g for g in (state.grammar, state.latest_grammar)}
        self.learner = Learner(grammars, self.learn_roots, self.cache_dir,
                               self.limits.learned_modules)  # fmt: skip
        self._freeze()

    def _freeze(self) -> None:
        # Requests write to their copy of the host's memory; objects the collector would visit
        # (and so copy) in every one of them are set aside instead.
        gc.collect()
        gc.freeze()

    def serve(self, jobs_fd: int, answers_fd: int, started: float | None) -> None:
        """Say Ready (unless `started` is None: the ruff runner), then answer jobs until the
        server (or the host) closes `jobs_fd`."""
        self.out = FrameWriter(answers_fd)
        if started is not None:
            self.out.send(Ready(startup_s=time.monotonic() - started))
        os.set_blocking(jobs_fd, False)
        jobs = FrameReader(jobs_fd, ToHost)
        self.poller.register(jobs_fd, select.POLLIN)
        runner = self.ruff_runner
        if runner is not None:
            os.set_blocking(runner.answers_fd, False)
            self.poller.register(runner.answers_fd, select.POLLIN)
        while True:
            self._keep_spares()
            events = self.poller.poll(self._timeout_ms())
            for fd, _ in events:
                if runner is not None and fd == runner.answers_fd:
                    self._relay(runner)
                elif fd != jobs_fd:
                    self._read(fd)
                elif not jobs.feed():
                    return  # the server closed our stdin: it is gone or let us go
                else:
                    with contextlib.suppress(ProtocolError):
                        while (job := jobs.pending()) is not None:
                            self._take(job)
            self._collect()
            self._enforce_deadlines()
            self._expire_sessions()
            self._warm_next()
            if self.learner is not None and self.learner.settled() and not self._warming():
                self._renew_spares()

    def _relay(self, runner: RuffRunner) -> None:
        """The ruff runner's answers, to the server as they are."""
        if not runner.answers.feed():
            raise SystemExit("the ruff runner ended")  # the server starts another sandbox
        with contextlib.suppress(ProtocolError):
            while (frame := runner.answers.pending()) is not None:
                self.out.send(frame)

    def stop(self) -> None:
        for pid in list(self.children):
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)

    def _timeout_ms(self) -> int:
        now = time.monotonic()
        waits = [c.deadline - now for c in self.children.values() if c.job is not None]
        if any(not c.open_fds for c in self.children.values()):
            waits.append(0.005)  # its pipes closed, its exit to be collected
        if self.learner is not None and self.learner.pending:
            waits.append(0.1)  # to renew the spares once it is done
        waits += [c.idle_since + self.limits.session_idle_s - now
                  for c in self.sessions.values() if c.job is None]  # fmt: skip
        return max(0, int(min(waits) * 1000) + 1) if waits else -1

    # ----------------------------------------------------------------------------- children
    def _fork(self, kind: Kind, budget_s: float | None = None, nice: int = 0) -> Child:
        """A process for a job to come (a spare), of at most `budget_s` of CPU time (default:
        the budget of its kind's jobs), `nice` lower in priority (analysis only)."""
        job_r, job_w = os.pipe()
        with contextlib.suppress(OSError):
            fcntl.fcntl(job_w, fcntl.F_SETPIPE_SZ, JOB_PIPE_BYTES)
        if kind is Kind.ANALYSIS:
            out_r, out_w = os.pipe()
            pid = os.fork()
            if pid == 0:
                self._forget()
                analysis_process(self.analyser, self.limits, job_r, out_w,
                                 budget_s or self.limits.analysis_budget_s, nice)  # fmt: skip
            ours, theirs, err_r = (out_r,), (job_r, out_w), None
        else:
            (out_r, out_w), (err_r, err_w) = os.pipe(), os.pipe()
            pid = os.fork()
            if pid == 0:
                self._forget()
                ruff_process(self.ruff, self.limits, job_r, out_w, err_w)
            ours, theirs = (out_r, err_r), (job_r, out_w, err_w)
        for fd in theirs:
            os.close(fd)
        child = Child(pid, kind, job_w, out_r, err_r, open_fds=set(ours))
        for fd in ours:
            os.set_blocking(fd, False)
            self.poller.register(fd, select.POLLIN)
            self.by_fd[fd] = child
        self.children[pid] = child
        return child

    def _forget(self) -> None:
        """In a new process: drop the host's view of the others, whose jobs hold other
        students' text (their pipes are closed by the process itself: request.py)."""
        self.children.clear()
        self.by_fd.clear()
        self.sessions.clear()

    def _spares(self, kind: Kind) -> list[Child]:
        return [c for c in self.children.values()
                if c.kind is kind and c.job is None and not c.stale and c.user is None]  # fmt: skip

    def _keep_spares(self) -> None:
        now = time.monotonic()
        for kind in self.kinds:
            if now < self.spares_paused_until.get(kind, 0.0):
                continue
            for _ in range(self.limits.concurrent_requests - len(self._spares(kind))):
                self._fork(kind)

    def _spare_died(self, kind: Kind) -> None:
        """A spare that ended before its job: the next ones wait, twice as long each time in a
        row (at most 30 s), so a spare that cannot start does not spin the machine."""
        self.spare_failures[kind] = failures = self.spare_failures.get(kind, 0) + 1
        self.spares_paused_until[kind] = time.monotonic() + min(0.1 * 2**failures, 30.0)

    def _warming(self) -> bool:
        return bool(self.warm_later) or any(c.job and c.job.id < 0 for c in self.children.values())

    def _renew_spares(self) -> None:
        """The spares were forked before the host learnt more: let them go (each exits when its
        job pipe closes) and fork new ones, which have it."""
        self._freeze()
        for child in self._spares(Kind.ANALYSIS):
            self._let_go(child)

    def _let_go(self, child: Child) -> None:
        """A process not needed any more: it exits when its job pipe closes."""
        child.stale = True
        if child.job_fd is not None:
            os.close(child.job_fd)
            child.job_fd = None
        if child.user is not None and self.sessions.get(child.user) is child:
            del self.sessions[child.user]

    def _expire_sessions(self) -> None:
        idle_s = self.limits.session_idle_s
        now = time.monotonic()
        for child in list(self.sessions.values()):
            if child.job is None and now - child.idle_since >= idle_s:
                self._let_go(child)

    def _keep_session(self, child: Child) -> None:
        """A student's process, answered: it waits for their next job, or goes."""
        child.job, child.answered, child.deadline = None, False, math.inf
        child.served += 1
        other = self.sessions.get(child.user) if child.user is not None else None
        if (
            child.user is None
            or child.served >= self.limits.session_requests
            or (
                other is not None and other is not child  # the student has one already
            )
        ):
            self._let_go(child)
            return
        child.idle_since = time.monotonic()
        self.sessions[child.user] = child
        idle = sorted((c for c in self.sessions.values() if c.job is None),
                      key=lambda c: c.idle_since)  # fmt: skip
        for oldest in idle[: max(0, len(self.sessions) - self.limits.sessions)]:
            self._let_go(oldest)  # the least recently served student's first

    def _warm_next(self) -> None:
        """The next WARM_LATER text, analysed by a process of its own once the last is done;
        its answer goes nowhere (a job of ours has a negative id), its parses are learnt."""
        if not self.warm_later or any(c.job and c.job.id < 0 for c in self.children.values()):
            return
        code, line, column = self.warm_later.popleft()
        budget_s = self.limits.warm_up_budget_s
        child = self._fork(Kind.ANALYSIS, budget_s=budget_s, nice=WARM_NICE)
        job = Job(id=-len(self.warm_later) - 1, op=Op.COMPLETE, code=code, line=line,
                  column=column, robot="crowbot")  # fmt: skip
        self._give(child, job, budget_s)

    def _take(self, job: Job) -> None:
        busy = sum(1 for c in self.children.values()
                   if c.job is not None and c.job.id >= 0 and not c.answered)  # fmt: skip
        if busy >= 2 * self.limits.concurrent_requests:  # the server's gate should not let it
            self._send(Refused(job.id, Cause.BUSY, "the editor's analysis is busy; it answers "
                                  "again in a moment"))  # fmt: skip
            return
        kind = Kind.RUFF if job.op in RUFF_OPS else Kind.ANALYSIS
        if kind not in self.kinds and self.ruff_runner is not None:
            self.ruff_runner.jobs.send(job)
            return
        child = self.sessions.get(job.user) if kind is Kind.ANALYSIS else None
        if child is None or child.job is not None or child.stale:
            spares = self._spares(kind)
            child = spares[0] if spares else self._fork(kind)
            if kind is Kind.ANALYSIS:
                child.user = job.user  # its jobs from now on: this student's only
        self._give(child, job, self.limits.budget_s(job.op))

    def _give(self, child: Child, job: Job, budget_s: float) -> None:
        child.job = job
        child.budget_s = budget_s
        child.deadline = time.monotonic() + budget_s
        with contextlib.suppress(OSError):  # it died waiting: its end says how
            FrameWriter(child.job_fd).send(job)
        if child.kind is Kind.RUFF or job.id < 0:  # one job only
            os.close(child.job_fd)
            child.job_fd = None

    def _read(self, fd: int) -> None:
        child = self.by_fd.get(fd)
        if child is None:
            return
        try:
            chunk = os.read(fd, READ_BYTES)
        except BlockingIOError:
            return
        except OSError:
            chunk = b""
        if not chunk:
            self._close(child, fd)
            return
        if child.kind is Kind.ANALYSIS:
            child.out += chunk
            self._take_frames(child)
            return
        buffer = child.out if fd == child.out_fd else child.err
        buffer += chunk
        cap = self.limits.answer_bytes
        if fd == child.out_fd and child.job is not None and child.job.op is Op.RUFF_CHECK:
            cap = self.limits.ruff_check_output_bytes
        if len(buffer) > cap:  # more than we take back: what came is the answer
            del buffer[cap:]
            child.truncated = True
            self._kill(child)

    def _take_frames(self, child: Child) -> None:
        buffer = child.out
        try:
            while len(buffer) >= FRAME_LENGTH.size:
                (length,) = FRAME_LENGTH.unpack_from(buffer)
                if length > self.limits.answer_bytes:
                    raise ValueError("answer too large")
                if len(buffer) < FRAME_LENGTH.size + length:
                    break
                frame = FROM_REQUEST.decode(bytes(buffer[4 : 4 + length]))
                del buffer[: 4 + length]
                if isinstance(frame, Parsed):
                    if self.learner is not None:
                        self.learner.note(frame)
                elif child.job is not None and not child.answered:
                    self._answer(child, frame)
                else:  # an answer before its job, or a second one: not our process any more
                    raise ValueError("unexpected answer")
        except (ValueError, msgspec.DecodeError):
            if child.job is not None and not child.answered:
                self._answer(child, Done(error="the analysis sent an answer that could not "
                                         "be read"))  # fmt: skip
            self._kill(child)

    def _answer(self, child: Child, done: Done) -> None:
        """An analysis request's Done is its answer, sent at once; its exit comes after."""
        child.answered = True
        self._log(child, "answered" if done.result is not None else f"refused ({done.cause})")
        if done.result is not None:
            self._send(Answer(child.job.id, done.result))
        else:
            self._send(Refused(child.job.id, done.cause, done.error or "the analysis failed"))
        if done.result is None or child.job.id < 0:
            self._let_go(child)  # a failed process does not go on (request.py); ours go
        else:
            self._keep_session(child)

    def _kill(self, child: Child) -> None:
        """End a process whose answer is complete, spoilt or late; it is collected as usual."""
        with contextlib.suppress(ProcessLookupError):
            os.kill(child.pid, signal.SIGKILL)
        for fd in list(child.open_fds):
            self._close(child, fd)

    def _close(self, child: Child, fd: int) -> None:
        if fd in child.open_fds:
            child.open_fds.discard(fd)
            self.poller.unregister(fd)
            del self.by_fd[fd]
            os.close(fd)

    def _collect(self) -> None:
        """Reap the processes whose pipes have all closed; answer for those that did not."""
        for pid, child in list(self.children.items()):
            if child.open_fds:
                continue
            exited, status, usage = os.wait4(pid, os.WNOHANG)
            if not exited:
                continue
            del self.children[pid]
            if child.user is not None and self.sessions.get(child.user) is child:
                del self.sessions[child.user]
            if child.job_fd is not None:
                os.close(child.job_fd)
            if child.job is None and not child.stale and child.user is None:
                self._spare_died(child.kind)
            elif child.job is not None:
                self.spare_failures.pop(child.kind, None)
                if not child.answered:
                    self._finish(child, status, usage.ru_utime + usage.ru_stime)

    def _enforce_deadlines(self) -> None:
        now = time.monotonic()
        for pid, child in list(self.children.items()):
            if child.job is None or now < child.deadline:
                continue
            self._kill(child)
            os.waitpid(pid, 0)
            del self.children[pid]
            self._let_go(child)
            if child.answered:
                continue  # answered, then slow to exit
            self._log(child, "stopped at its deadline")
            self._send(endings.late(child.job, child.budget_s))

    def _finish(self, child: Child, status: int, cpu_s: float) -> None:
        """The answer of a process that ended without sending one (ruff's, always)."""
        self._log(child, f"ended (status {status})")
        if child.kind is Kind.RUFF:
            answer = endings.ruff_ended(child.job, child.budget_s, status, cpu_s, child.out,
                                        child.err, child.truncated, self.limits)  # fmt: skip
        else:
            answer = endings.analysis_ended(child.job, child.budget_s, status, cpu_s,
                                            self.limits)  # fmt: skip
        self._send(answer)

    def _send(self, frame: Answer | Refused) -> None:
        if frame.id >= 0:  # not a warm-up job of ours
            self.out.send(frame)

    def _log(self, child: Child, what: str) -> None:
        """One line on the log per job (the server logs the host's lines at debug level)."""
        took_ms = (time.monotonic() - child.deadline + child.budget_s) * 1000
        learning = self.learner.pending if self.learner is not None else 0
        # The student by a digest of their id: which process served whom, and nothing more.
        student = hashlib.sha256((child.user or "").encode()).hexdigest()[:8]
        print(f"job {child.job.id} {child.job.op}: {what} after {took_ms:.1f} ms in process "
              f"{child.pid} for student {student} ({learning} modules to learn)",
              file=sys.stderr, flush=True)  # fmt: skip


def main(argv: list[str]) -> int:
    started = time.monotonic()
    settings = json.loads(argv[0])
    # The frames keep fds of their own; 0 and 1 become /dev/null and the log, so a stray
    # print from a library cannot break the protocol.
    jobs_fd, answers_fd = os.dup(0), os.dup(1)
    os.dup2(os.open(os.devnull, os.O_RDONLY), 0)
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    limits = settings["limits"]
    address_space, request_memory = limits["host_address_space_bytes"], limits[
        "request_memory_bytes"]  # fmt: skip
    # The host's own cap, and room above it for a request's (which a request cannot raise).
    resource.setrlimit(resource.RLIMIT_AS, (address_space, address_space + request_memory))
    sys.setrecursionlimit(3000)  # jedi recurses on nested code; deeper fails as RecursionError
    runner = _start_ruff_runner(settings, (jobs_fd, answers_fd))
    host = Host(settings, (Kind.ANALYSIS,), runner)
    host.warm_up()
    try:
        host.serve(jobs_fd, answers_fd, started)
    finally:
        host.stop()
        with contextlib.suppress(ProcessLookupError):
            os.kill(runner.pid, signal.SIGKILL)
    return 0


def _start_ruff_runner(settings: dict, server_fds: tuple[int, int]) -> RuffRunner:
    """A twin of the host forked now, before jedi is loaded, that forks ruff's processes: from
    a small process instead of the warm host each fork, exec and exit is cheaper (a format's
    p50 on the 2-core lab machine at load 3-6: 65-85 ms forked from the warm host, 20-33 ms
    from the twin; ruff alone, unsandboxed, 7-11 ms). It gets ruff's jobs from the host and
    answers through it."""
    jobs_r, jobs_w = os.pipe()
    answers_r, answers_w = os.pipe()
    pid = os.fork()
    if pid == 0:
        status = 1
        try:
            for fd in (*server_fds, jobs_w, answers_r):
                os.close(fd)
            twin = Host(settings, (Kind.RUFF,))
            try:
                twin.serve(jobs_r, answers_w, None)
            finally:
                twin.stop()
            status = 0
        finally:
            os._exit(status)
    os.close(jobs_r)
    os.close(answers_w)
    # Each way holds what the gate lets through at once (two jobs of the largest file), so
    # neither waits on the other; past that, the server's deadline ends a stuck sandbox.
    for fd in (jobs_w, answers_r):
        with contextlib.suppress(OSError):
            fcntl.fcntl(fd, fcntl.F_SETPIPE_SZ, JOB_PIPE_BYTES)
    return RuffRunner(pid, FrameWriter(jobs_w), answers_r, FrameReader(answers_r, ToServer))
