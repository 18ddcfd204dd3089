"""One sandboxed child as the parent sees it: start it, send it frames, time it, kill it.

`NodeProcess` owns the child's pipes (protocol in, protocol out, log stream) and its state
(an explicit enum with checked transitions). Every wait has a deadline: a node that does not
reply within its budget is killed, and the reply says so; a child that dies (a signal, the
memory cgroup, a broken pipe) becomes an `Exited` with outcome CRASHED and a sentence why.
Nothing a node does raises in the caller; driving a node out of order raises NodeUsageError.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import select
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict
from enum import StrEnum

from sandbox import bwrap
from sandbox.artifact_intake import accept_artifacts
from sandbox.cgroups import Cgroups, CgroupsV2, NodeCgroup, enter_and_exec
from sandbox.limits import Limits
from sandbox.logstream import LogStream
from sandbox.protocol import (
    Api,
    Artifact,
    Drawing,
    Envelope,
    Exited,
    Finishing,
    FrameReader,
    FrameWriter,
    GraphTopic,
    LibraryLoading,
    Load,
    NodeInfo,
    Outcome,
    ProtocolError,
    Ready,
    Shutdown,
    ToParent,
    Wake,
    Yield,
)
from sandbox.seccomp import write_stage1_bpf

log = logging.getLogger("robodojo.sandbox")


class NodeState(StrEnum):
    STARTING = "starting"  # spawned, imports running
    IDLE = "idle"  # Ready received, waiting in the pool for code
    RUNNING = "running"  # woken (or loaded), computing until it yields
    SLEEPING = "sleeping"  # yielded, waiting for the next wake
    FINISHING = "finishing"  # ended its part in the run; hooks, figures and files to come
    EXITED = "exited"


_TRANSITIONS = {
    NodeState.STARTING: {NodeState.IDLE, NodeState.EXITED},
    NodeState.IDLE: {NodeState.RUNNING, NodeState.EXITED},
    NodeState.RUNNING: {NodeState.SLEEPING, NodeState.FINISHING, NodeState.EXITED},
    NodeState.FINISHING: {NodeState.EXITED},
    NodeState.SLEEPING: {NodeState.RUNNING, NodeState.EXITED},
    NodeState.EXITED: set(),
}


class NodeUsageError(RuntimeError):
    """The caller used a NodeProcess out of order (a bug in the server, not in student code)."""


class NodeProcess:
    """One sandboxed child. Not thread-safe: one caller drives it."""

    def __init__(
        self,
        limits: Limits,
        sandboxed: bool,
        font_cache: str | None = None,
        cgroups: Cgroups | CgroupsV2 | None = None,
        preload: bool = True,
        message_types: tuple[str, ...] = (),
    ) -> None:
        """`preload`: import the heavy libraries (numpy, matplotlib, scipy, scikit-fuzzy,
        rclpy) before Ready, for a process that waits in the warm pool; without it the node is
        Ready in a fraction of the time and the student's imports load what it uses.
        `message_types`: ROS 1 type names whose classes (and ROS 2 twins) it builds before Ready."""
        self.limits = limits
        self.sandboxed = sandboxed
        self.name = "(pool)"
        self.state = NodeState.STARTING
        self.exited: Exited | None = None
        self.startup_ms: float | None = None
        self.time_s = 0.0
        to_child_r, to_child_w = os.pipe()
        from_child_r, from_child_w = os.pipe()
        log_r, log_w = os.pipe()
        # The child finds the protocol pipes by number (inherited fds keep their numbers
        # through bwrap), so nothing has to be moved between fork and exec.
        settings = {
            "rlimits": _rlimits(limits),
            "nice": limits.nice,
            "seal": sandboxed,
            "preload": preload,
            "message_types": list(message_types),
            "fd_in": to_child_r,
            "fd_out": from_child_w,
        }
        with tempfile.TemporaryFile() as bpf:
            write_stage1_bpf(bpf)
            bpf.seek(0)
            seccomp_fd = os.dup(bpf.fileno())
        self._unsafe_scratch: tempfile.TemporaryDirectory | None = None
        self.cgroup: NodeCgroup | None = None
        try:
            if sandboxed:
                command = bwrap.build_command(
                    seccomp_fd, limits.scratch_bytes, [json.dumps(settings)], font_cache
                )
                # bwrap (pid 1 inside, its /proc/1/environ readable by the node) and the shell
                # that moves it into its cgroup start with the sandbox's own environment, in
                # "/": nothing of the server's environment or working directory goes in.
                env, cwd = bwrap.sandbox_environment(font_cache), "/"
                if cgroups is not None:
                    self.cgroup = cgroups.create(limits)
                    command = enter_and_exec(self.cgroup, command)
            else:
                # DANGER path: a plain child process in a throw-away directory.
                self._unsafe_scratch = tempfile.TemporaryDirectory(prefix="robodojo-unsafe-")
                cwd = self._unsafe_scratch.name
                bootstrap = bwrap.runner_bootstrap(_source_root())
                command = [sys.executable, "-I", "-S", "-c", bootstrap, json.dumps(settings)]
                env = bwrap.node_environment(cwd)
                if font_cache:
                    env["ROBODOJO_FONT_CACHE"] = font_cache
            self.process = subprocess.Popen(
                command,
                stdin=subprocess.DEVNULL,
                stdout=log_w,
                stderr=log_w,
                pass_fds=(to_child_r, from_child_w, seccomp_fd),
                env=env,
                cwd=cwd,
            )
        finally:
            for fd in (to_child_r, from_child_w, log_w, seccomp_fd):
                os.close(fd)
        os.set_blocking(from_child_r, False)
        os.set_blocking(log_r, False)
        self._writer = FrameWriter(to_child_w)
        self._reader = FrameReader(from_child_r, ToParent)
        self._fds = (to_child_w, from_child_r, log_r)
        self.logs = LogStream(log_r, limits.log_total_bytes, limits.log_line_bytes)
        # One poller for the node's life: registering fds anew costs microseconds every step.
        self._poller = select.poll()
        self._poller.register(from_child_r, select.POLLIN)
        self._poller.register(log_r, select.POLLIN)
        self._proto_open = self._log_open = True
        # While a library loads (protocol.LibraryLoading): the step's time left [s], its budget
        # [s] and its name, given back when the load is done.
        self._paused: tuple[float, float, str] | None = None

    # ----------------------------------------------------------------------------- state
    def _move(self, new: NodeState) -> None:
        if new not in _TRANSITIONS[self.state]:
            raise NodeUsageError(f"node {self.name}: cannot go from {self.state} to {new}")
        self.state = new

    @property
    def pid(self) -> int:
        return self.process.pid

    def wait_ready(self, timeout_s: float | None = None) -> bool:
        """Wait for the child's Ready; False if it died or took longer than its budget."""
        if self.state is NodeState.IDLE:
            return True
        if self.state is not NodeState.STARTING:
            return False
        self._expect(timeout_s or self.limits.startup_budget_s, "start-up")
        reply = self._receive_until(self._deadline)
        if isinstance(reply, Ready):
            self.startup_ms = reply.startup_ms
            self._move(NodeState.IDLE)
            return True
        if self.state is not NodeState.EXITED:
            self._overdue()
        return False

    # ----------------------------------------------------------------------------- driving
    def load(
        self,
        code: str,
        filename: str,
        api: Api,
        info: NodeInfo,
        files: list[Artifact] | None = None,
    ) -> Yield | Exited:
        """Give the idle node its code (and the workspace's data files for its working
        directory); returns its first Yield (setup done) or its end."""
        if not self.wait_ready():
            return self._end_reply()
        self.name = info.node_name
        self.time_s = info.start_time_s
        self._move(NodeState.RUNNING)
        self._send(Load(code=code, filename=filename, api=api, info=info, files=files or []))
        self._expect(self.limits.first_step_budget_s, "first step")
        return self.poll_reply(None)

    def wake(
        self, time_s: float, deliveries: list[Envelope], graph: list[GraphTopic] | None = None
    ) -> Yield | Finishing | Exited:
        """Wake the sleeping node at simulated (or wall) time `time_s` with new messages and
        wait for it to sleep again (or end)."""
        self.begin_wake(time_s, deliveries, graph)
        return self.poll_reply(None)

    def begin_wake(
        self, time_s: float, deliveries: list[Envelope], graph: list[GraphTopic] | None = None
    ) -> None:
        """Wake the node without waiting; collect its reply with `poll_reply` (a realtime run
        drives several nodes at once this way). `graph`: the run's topics, if they changed."""
        self.time_s = time_s
        self._move(NodeState.RUNNING)
        self._send(Wake(time_s=time_s, deliveries=deliveries, graph=graph))
        self._expect(self.limits.step_budget_s, "step")

    def poll_reply(self, timeout_s: float | None) -> Yield | Finishing | Exited | None:
        """The running node's reply, waiting at most `timeout_s` (None: until its budget runs
        out). None means it is still computing within its budget. After a Finishing the node
        has the end budget (limits.shutdown_budget_s) for its Exited: see `poll_finished`."""
        if self.state is not NodeState.RUNNING:
            raise NodeUsageError(f"node {self.name} is {self.state}, not waiting for a reply")
        give_up = None if timeout_s is None else time.monotonic() + timeout_s
        while True:
            until = self._deadline if give_up is None else min(self._deadline, give_up)
            reply = self._receive_until(until)
            if isinstance(reply, Drawing):
                self._drawing()
            elif isinstance(reply, LibraryLoading):
                self._library_loading(reply.done)
            else:
                break
        if isinstance(reply, Yield):
            self._move(NodeState.SLEEPING)
            return reply
        if isinstance(reply, Finishing):
            self._move(NodeState.FINISHING)
            self._expect(self.limits.shutdown_budget_s, "end")
            return reply
        if isinstance(reply, Exited):
            self._finish(reply)
            return reply
        if self.state is NodeState.EXITED:
            return self.exited
        if time.monotonic() >= self._deadline:
            return self._overdue()
        return None

    @property
    def reply_fds(self) -> tuple[int, int]:
        """The fds that become readable when the node replies or logs (for a caller's poll)."""
        return (self._fds[1], self._fds[2]) if self._fds else ()

    def poll_finished(self, timeout_s: float = 0.0) -> Exited | None:
        """A finishing node's Exited if it has come (reading what arrived so far), or its end
        if it overran its end budget; None while it is still within it."""
        if self.state is NodeState.EXITED:
            return self.exited
        if self.state is not NodeState.FINISHING:
            raise NodeUsageError(f"node {self.name} is {self.state}, not finishing")
        until = min(self._deadline, time.monotonic() + timeout_s)
        reply = self._receive_until(until)
        while isinstance(reply, Drawing | LibraryLoading):  # it has the end budget already
            reply = self._receive_until(until)
        if isinstance(reply, Exited):
            self._finish(reply)
            return reply
        if self.state is NodeState.EXITED:
            return self.exited
        if reply is not None:
            return self.kill(
                f"node {self.name} sent {type(reply).__name__} after it finished",
                Outcome.CRASHED,
            )
        if time.monotonic() >= self._deadline:
            return self._overdue()
        return None

    def shutdown(self, reason: str) -> Exited:
        """Ask the node to stop (on_shutdown hooks run, artifacts are collected)."""
        if self.state is NodeState.EXITED:
            return self.exited
        if self.state is NodeState.FINISHING:
            # A node that finished long ago may be blocked writing a large Exited: read it
            # even when its end budget has passed meanwhile.
            self._deadline = max(self._deadline, time.monotonic() + 1.0)
            reply = self.poll_finished(self._deadline - time.monotonic())
            return reply if reply is not None else self._overdue()
        if self.state is not NodeState.SLEEPING:
            return self.kill(f"stopped: {reason}", Outcome.SHUTDOWN)
        self._move(NodeState.RUNNING)
        self._send(Shutdown(reason=reason))
        self._expect(self.limits.shutdown_budget_s, "shutdown")
        reply = self.poll_reply(None)
        if isinstance(reply, Yield):  # it slept again: it may not, the run is over
            reply = self.kill(
                f"stopped: {reason} (it kept running after shutdown)", Outcome.SHUTDOWN
            )
        elif isinstance(reply, Finishing):
            reply = self.shutdown(reason)
        return reply

    def kill(self, reason: str, outcome: Outcome = Outcome.KILLED) -> Exited:
        """End the child now (SIGKILL to bubblewrap takes the whole sandbox with it)."""
        if self.state is not NodeState.EXITED:
            self._finish(Exited(outcome=outcome, reason=reason))
        return self.exited

    def close(self) -> None:
        """Release the process and its pipes (kills it if still alive)."""
        if self.state is not NodeState.EXITED:
            self.kill("closed")
        for fd in self._fds:
            with contextlib.suppress(OSError):
                os.close(fd)
        self._fds = ()
        if self._unsafe_scratch is not None:
            self._unsafe_scratch.cleanup()
        if self.cgroup is not None:
            self.cgroup.remove()

    # ----------------------------------------------------------------------------- internals
    def _send(self, frame: object) -> None:
        # A dead child makes the write fail; the next receive reports how it ended.
        with contextlib.suppress(OSError):
            self._writer.send(frame)

    def _expect(self, budget_s: float, what: str) -> None:
        """Start the clock on a reply: it must come within `budget_s`."""
        self._budget_s, self._budget_what = budget_s, what
        self._deadline = time.monotonic() + budget_s
        self._paused = None

    def _drawing(self) -> None:
        """Saving a figure may take seconds: this step gets the end budget instead."""
        paused, left_s = self._paused, self._deadline - time.monotonic()
        self._expect(max(self.limits.shutdown_budget_s, left_s), "drawing")
        if paused is not None:  # drawing while a library loads: the end budget after it too
            self._paused = (max(self.limits.shutdown_budget_s, paused[0]), *self._budget())

    def _library_loading(self, done: bool) -> None:
        """The step's clock stops while a library loads (protocol.LibraryLoading): the load
        gets the end budget, and the step then has the time it had left before."""
        if not done:
            left_s = self._deadline - time.monotonic()
            saved = (left_s, *self._budget())
            self._expect(max(self.limits.shutdown_budget_s, left_s), "library loading")
            self._paused = saved
        elif self._paused is not None:
            left_s, budget_s, what = self._paused
            self._expect(budget_s, what)
            self._deadline = time.monotonic() + left_s

    def _budget(self) -> tuple[float, str]:
        return self._budget_s, self._budget_what

    def _overdue(self) -> Exited:
        return self.kill(
            f"node {self.name} exceeded its {self._budget_s:g} s {self._budget_what} budget "
            f"at t={self.time_s:.3f} s"
        )

    def _end_reply(self) -> Exited:
        if self.exited is None:
            self._finish(Exited(outcome=Outcome.CRASHED, reason=f"node {self.name} ended"))
        return self.exited

    def _receive_until(self, until: float) -> object | None:
        """The next frame if one arrives before monotonic time `until`; None if not (or if the
        child died, which is then recorded as its end). Drains the log stream meanwhile."""
        poller, proto_fd, log_fd = self._poller, self._fds[1], self._fds[2]
        polled_once = False
        while True:
            try:
                frame = self._reader.pending()
            except ProtocolError as error:
                self.kill(f"node {self.name} broke the protocol: {error}", Outcome.CRASHED)
                return None
            if isinstance(frame, Exited):
                # The node's collector is the student's to replace: its files are held to the
                # caps here, on our side of the pipe (sandbox/artifact_intake.py).
                return accept_artifacts(frame, self.limits)
            if frame is not None:
                return frame
            if not self._proto_open:
                if self._log_open:
                    self.logs.drain()
                self._finish(Exited(outcome=Outcome.CRASHED, reason=self._death_reason()))
                return None
            remaining = until - time.monotonic()
            if remaining <= 0:
                if polled_once:
                    return None
                remaining = 0.0  # a deadline already past still reads what has arrived
            polled_once = True
            for fd, _event in poller.poll(remaining * 1000.0):
                if fd == log_fd:
                    if not self.logs.drain():
                        poller.unregister(log_fd)
                        self._log_open = False
                elif fd == proto_fd and not self._reader.feed():
                    poller.unregister(proto_fd)
                    self._proto_open = False

    def _death_reason(self) -> str:
        try:
            code = self.process.wait(timeout=2.0)
        except subprocess.TimeoutExpired:
            self.process.kill()
            code = self.process.wait()
        if self.cgroup is not None and self.cgroup.oom_killed():
            return (
                f"node {self.name} ran out of memory (its cap is "
                f"{self.limits.memory_bytes // (1024 * 1024)} MiB) at t={self.time_s:.3f} s"
            )
        # bwrap (and the cgroup shell before it) exits with 128 + N when the node died of
        # signal N; a plain child shows it as -N.
        signal_number = -code if code < 0 else code - 128 if code > 128 else None
        if signal_number:
            return (
                f"node {self.name} was killed by signal {signal_number} "
                f"({_signal_name(signal_number)}) at t={self.time_s:.3f} s"
            )
        return f"node {self.name} died unexpectedly (exit code {code}) at t={self.time_s:.3f} s"

    def _finish(self, exited: Exited) -> None:
        self.exited = exited
        self.state = NodeState.EXITED
        if self.process.poll() is None:
            self.process.kill()
        try:
            self.process.wait(timeout=5.0)
        except subprocess.TimeoutExpired:
            log.error("node %s (pid %s) did not die after SIGKILL", self.name, self.pid)
        if self._fds:
            self.logs.drain()


def _signal_name(number: int) -> str:
    try:
        return signal.Signals(number).name
    except ValueError:
        return "unknown signal"


def _rlimits(limits: Limits) -> dict[str, int]:
    fields = asdict(limits)
    return {
        key: fields[key]
        for key in ("address_space_bytes", "cpu_seconds", "open_files", "file_size_bytes")
    }


def _source_root() -> str:
    return os.path.dirname(bwrap.sandbox_package_dir())
