"""The parent side of sandboxed nodes: start them, talk to them, time them, kill them.

    launcher = Launcher()                      # refuses to run if bubblewrap is missing
    node = launcher.start("follower")          # from the warm pool: imports already done,
                                               # or a cold one: Ready in ~0.1 s, lazy imports
    reply = node.load(code, "follower.py", Api.AUTO, info)   # -> Yield | Exited
    reply = node.wake(0.1, deliveries)         # -> Yield | Exited, within the step budget
    exited = node.shutdown("finished: duration reached")
    launcher.close()

Layers (codejail's shape): `Launcher` (policy: sandbox or refuse, the warm pool) ->
`NodeProcess` (sandbox/node_process.py: one child, frames, budgets, logs, kill) ->
`sandbox.bwrap` (the walls) and
`sandbox.seccomp` (the filters). Limits come from `sandbox.limits`.

A node that does not yield within its budget is killed, and the reply says so; a child that
dies (a signal, a broken pipe) turns into an `Exited` with outcome CRASHED. Nothing a node does
raises in the caller except misuse of this API.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from collections.abc import Iterable

from sandbox import bwrap, cgroups
from sandbox.limits import DEFAULT_LIMITS, Limits
from sandbox.node_process import NodeProcess, NodeState, NodeUsageError

__all__ = ["DANGER", "Launcher", "NodeProcess", "NodeState", "NodeUsageError"]

log = logging.getLogger("robodojo.sandbox")

DANGER = (
    "DANGER: running student code WITHOUT a sandbox (--unsafe-no-sandbox): it can read and "
    "write every file this server can, reach the network and kill processes"
)


class Launcher:
    """Starts sandboxed nodes, keeping `pool_size` warm ones ready.

    With `unsafe_no_sandbox=False` (the default) it refuses to run where bubblewrap cannot
    build a sandbox; with True it runs plain child processes and logs a DANGER line every time.
    `message_types`: ROS 1 type names ("sensor_msgs/LaserScan") whose classes, and their ROS 2
    twins, the warm nodes build before they wait in the pool (the robots' topic types: built at
    a node's first use they cost 0.3-13 ms of its start).
    """

    def __init__(
        self,
        limits: Limits = DEFAULT_LIMITS,
        pool_size: int = 2,
        unsafe_no_sandbox: bool = False,
        message_types: Iterable[str] = (),
    ) -> None:
        self.limits = limits
        self.pool_size = pool_size
        self.message_types = _checked_message_types(message_types)
        problem = bwrap.probe()
        if problem and not unsafe_no_sandbox:
            raise bwrap.SandboxUnavailable(
                f"cannot run student code safely: {problem}. Install bubblewrap (apt-get install "
                "bubblewrap) on a kernel with user namespaces, or, on a trusted machine only, "
                "start with --unsafe-no-sandbox."
            )
        self.sandboxed = not unsafe_no_sandbox
        self.font_cache = bwrap.prepare_font_cache()
        bwrap.precompile_package()  # read-only inside: compile here or at every node start
        self.cgroups = cgroups.detect() if self.sandboxed else None
        if self.sandboxed:
            log.info("node limits: %s", cgroups.describe(self.cgroups))
        self._pool: deque[NodeProcess] = deque()
        self._lock = threading.Lock()
        self._closed = False
        self._refill_wanted = threading.Event()
        self._refiller = threading.Thread(
            target=self._refill_loop, name="sandbox-pool", daemon=True
        )
        if pool_size > 0:
            self._refiller.start()
            self._refill_wanted.set()

    def _spawn(self, preload: bool) -> NodeProcess:
        return NodeProcess(
            self.limits,
            self.sandboxed,
            self.font_cache,
            self.cgroups,
            preload,
            self.message_types if preload else (),
        )

    def _refill_loop(self) -> None:
        while not self._closed:
            self._refill_wanted.wait()
            self._refill_wanted.clear()
            while not self._closed:
                with self._lock:
                    if len(self._pool) >= self.pool_size:
                        break
                node = self._spawn(preload=True)  # it waits anyway: import everything now
                node.wait_ready()
                with self._lock:
                    if self._closed:
                        node.close()
                        return
                    if node.state is NodeState.IDLE:
                        self._pool.append(node)
                    else:
                        node.close()
                        log.error("a warm sandbox process failed to start: %s", node.exited)
                        time.sleep(1.0)  # do not spin if the machine cannot start them

    def start(self, name: str) -> NodeProcess:
        """A node ready for `load()`: a warm one if the pool has one (its heavy libraries
        already imported), else a fresh one that imports only what the student's code does."""
        if self._closed:
            raise NodeUsageError("the launcher is closed")
        if not self.sandboxed:
            log.warning("%s (node %s)", DANGER, name)
        node = None
        with self._lock:
            while self._pool:
                candidate = self._pool.popleft()
                if candidate.process.poll() is None:
                    node = candidate
                    break
                candidate.close()
        self._refill_wanted.set()
        if node is None:  # someone waits for this one: import only what the student does
            node = self._spawn(preload=False)
        node.name = name
        return node

    @property
    def warm_count(self) -> int:
        """How many warm nodes wait in the pool now (for the lab's status)."""
        with self._lock:
            return len(self._pool)

    def close(self) -> None:
        self._closed = True
        self._refill_wanted.set()
        with self._lock:
            while self._pool:
                self._pool.popleft().close()


def _checked_message_types(names: Iterable[str]) -> tuple[str, ...]:
    """The names, once each is known to have a class in both dialects: a name we do not
    provide fails here, with the message types' own sentence, not in every warm process."""
    from sandbox.msgs2.bridge import build_both_dialects

    checked = tuple(dict.fromkeys(names))
    build_both_dialects(checked)
    return checked
