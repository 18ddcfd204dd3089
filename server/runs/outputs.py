"""What leaves a run while it runs, through sinks the run is given: every message (into the
recording, to a live observer), the nodes' log lines (and a real robot's own) and the run's
state changes. The engine calls `RunOutputs`; which sinks listen is decided by whoever builds
the run (server/runs/run.py), so the engine never asks whether anyone watches.

An observer (the web service's telemetry) is called on the run's own thread; its failures are
logged and never end the run.
"""

from __future__ import annotations

import logging
from typing import Protocol

from server.runs.recorder import Recorder
from server.runs.state import RunState

log = logging.getLogger("robodojo.runs")


class RunSink(Protocol):
    """One listener to what a run puts out. Called on the run's own thread."""

    def record(self, topic: str, type_name: str, time_ns: int, data: bytes) -> None: ...

    def log(self, node: str, lines: list[str]) -> None: ...

    def state(self, state: RunState, reason: str, time_s: float) -> None: ...


class RunObserver(Protocol):
    """Watches a run live (the web service's telemetry hub). Called on the run's own thread,
    so each method must be quick and must not raise; what it does with the data (coalescing,
    dropping for slow viewers) is its business, never the run's."""

    def on_message(self, topic: str, type_name: str, time_ns: int, data: bytes) -> None: ...

    def on_logs(self, node: str, lines: list[str]) -> None: ...

    def on_state(self, state: RunState, reason: str, time_s: float) -> None: ...


class RecordingSink:
    """Messages into the run's MCAP file, log lines into its log files (server/runs/recorder.py
    keeps both off the run's thread)."""

    def __init__(self, recorder: Recorder) -> None:
        self.recorder = recorder

    def record(self, topic: str, type_name: str, time_ns: int, data: bytes) -> None:
        self.recorder.record(topic, type_name, time_ns, data)

    def log(self, node: str, lines: list[str]) -> None:
        self.recorder.write_log(node, lines)

    def state(self, state: RunState, reason: str, time_s: float) -> None:
        pass  # the recording holds the result (metrics.json), not the transitions


class ObserverSink:
    """A `RunObserver` behind a guard: whatever it raises is logged, and an observer that fails
    on a message is dropped (one report, not one per message)."""

    def __init__(self, observer: RunObserver, run_id: str) -> None:
        self.observer: RunObserver | None = observer
        self.run_id = run_id

    def record(self, topic: str, type_name: str, time_ns: int, data: bytes) -> None:
        if self.observer is None:
            return
        try:
            self.observer.on_message(topic, type_name, time_ns, data)
        except Exception:
            log.exception("run %s: the observer failed on a message", self.run_id)
            self.observer = None

    def log(self, node: str, lines: list[str]) -> None:
        if self.observer is None:
            return
        try:
            self.observer.on_logs(node, list(lines))
        except Exception:
            log.exception("run %s: the observer failed on log lines", self.run_id)

    def state(self, state: RunState, reason: str, time_s: float) -> None:
        if self.observer is None:
            return
        try:
            self.observer.on_state(state, reason, time_s)
        except Exception:  # a viewer's problem never ends a run
            log.exception("run %s: the observer failed on a state change", self.run_id)


class RunOutputs:
    """The sinks of one run, fed in order (the recording is put first, so a viewer never sees
    a message before the file has it)."""

    def __init__(self, *sinks: RunSink) -> None:
        self.sinks: tuple[RunSink, ...] = sinks

    def add(self, sink: RunSink, first: bool = False) -> None:
        self.sinks = (sink, *self.sinks) if first else (*self.sinks, sink)

    def remove(self, sink: RunSink) -> None:
        self.sinks = tuple(s for s in self.sinks if s is not sink)

    def record(self, topic: str, type_name: str, time_ns: int, data: bytes) -> None:
        """One message (serialized in the run's dialect) at run time `time_ns` [ns]."""
        for sink in self.sinks:
            sink.record(topic, type_name, time_ns, data)

    def log(self, node: str, lines: list[str]) -> None:
        """Lines of a node (or of the robot itself, node "robot")."""
        if lines:
            for sink in self.sinks:
                sink.log(node, lines)

    def state(self, state: RunState, reason: str, time_s: float) -> None:
        for sink in self.sinks:
            sink.state(state, reason, time_s)
