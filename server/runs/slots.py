"""The run's view of one sandboxed node: its process, when it wants waking, what it has said."""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from sandbox.node_process import NodeProcess, NodeState
from sandbox.protocol import Exited
from server.runs.metrics import NodeMetrics
from server.runs.outputs import RunOutputs
from server.runs.spec import NodeSpec

LOG_LINES_KEPT = 2000  # per node in memory (the recording keeps them all)


@dataclass
class NodeSlot:
    spec: NodeSpec
    process: NodeProcess | None = None
    wake_at_ns: int | None = 0  # None: spinning (wake on messages)
    # Topics whose messages wake the node before wake_at_ns (services, wait_for_message);
    # None: only wake_at_ns, or any message while spinning.
    wake_on: frozenset[str] | None = None
    graph_version: int = -1  # the bus graph version this node was last sent
    done: bool = False
    finishing: bool = False  # ended its part; its Exited (files, figures) is still to come
    exited: Exited | None = None
    last_wake_ns: int | None = None
    newest_sensor_s: float | None = None  # publication time of the newest robot message seen
    woken_at_wall: float = 0.0
    metrics: NodeMetrics = field(default_factory=NodeMetrics)
    logs: deque = field(default_factory=lambda: deque(maxlen=LOG_LINES_KEPT))

    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def computing(self) -> bool:
        """Woken and not answered yet (realtime only: a lockstep wake waits for the reply)."""
        return self.process is not None and self.process.state is NodeState.RUNNING

    def log(self, lines: list[str], outputs: RunOutputs) -> None:
        """Lines into the node's in-memory log (the live page's) and out to the run's sinks."""
        self.logs.extend(lines)
        outputs.log(self.name, lines)
