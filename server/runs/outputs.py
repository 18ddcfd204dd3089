"""What leaves a run while it runs: every message into the recording and to a live observer,
the nodes' log lines (and a real robot's own) into the log files and to the observer.
Mixed into Run; split from run.py so the loop and the plumbing each stay one concept.

An observer (the web service's telemetry) is called on the run's own thread; its failures are
logged and never end the run.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Protocol

from server.runs.state import RunState

if TYPE_CHECKING:
    from server.runs.run import NodeSlot, Run

log = logging.getLogger("robodojo.runs")
NS = 1_000_000_000


class RunObserver(Protocol):
    """Watches a run live (the web service's telemetry hub). Called on the run's own thread,
    so each method must be quick and must not raise; what it does with the data (coalescing,
    dropping for slow viewers) is its business, never the run's."""

    def on_message(self, topic: str, type_name: str, time_ns: int, data: bytes) -> None: ...

    def on_logs(self, node: str, lines: list[str]) -> None: ...

    def on_state(self, state: RunState, reason: str, time_s: float) -> None: ...


class RunOutputs:
    """Mixed into Run: the recording and the observer, fed from one place each."""

    def record(self: Run, topic: str, type_name: str, time_ns: int, data: bytes) -> None:
        """One message into the recording and, if someone watches, to the observer."""
        self.recorder.record(topic, type_name, time_ns, data)
        if self.observer is not None:
            try:
                self.observer.on_message(topic, type_name, time_ns, data)
            except Exception:
                log.exception("run %s: the observer failed on a message", self.run_id)
                self.observer = None  # one report, not one per message

    def _collect_logs(self: Run, slot: NodeSlot) -> None:
        if slot.process is None:
            return
        lines = slot.process.logs.take()
        if lines:
            self._log_lines(slot, lines)

    def _log_lines(self: Run, slot: NodeSlot, lines: list[str]) -> None:
        slot.logs.extend(lines)
        self._emit_logs(slot.name, lines)

    def _emit_logs(self: Run, node: str, lines: list[str]) -> None:
        """Lines of a node (or of the robot itself) into its log file and to the observer."""
        if not lines:
            return
        if self.recorder is not None:
            self.recorder.write_log(node, lines)
        if self.observer is not None:
            try:
                self.observer.on_logs(node, list(lines))
            except Exception:
                log.exception("run %s: the observer failed on log lines", self.run_id)

    def _tell_state(self: Run, state: RunState) -> None:
        if self.observer is not None:
            try:
                self.observer.on_state(state, self.reason, self.time_ns / NS)
            except Exception:  # a viewer's problem never ends a run
                log.exception("run %s: the observer failed on a state change", self.run_id)
