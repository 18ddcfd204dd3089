"""A run: a robot backend, one or more sandboxed nodes, a clock, a topic bus and a recording.

    run = Run(spec, launcher, out_dir, observer=hub)   # observer: optional, see RunObserver
    result = run.execute()          # blocking: call it from a worker thread or the CLI
    run.command(Pause()) / run.command(Button(True)) / run.stop()   # any thread, meanwhile

`Run` is the façade the service, the CLI and the tests hold. It puts the engine together: the
core (server/runs/core.py: lifecycle and routing, no threads), the sinks it writes to
(server/runs/outputs.py: the recording, a live observer), its command inbox
(server/runs/inbox.py) and the clock the spec asks for (server/runs/clocks.py). Nothing that goes
wrong in one run escapes `execute()`.
"""

from __future__ import annotations

import uuid
from pathlib import Path

from sandbox.launcher import Launcher
from sandbox.protocol import Clock
from server.runs import controls
from server.runs.builtin_host import BuiltinHost
from server.runs.bus import TopicBus
from server.runs.clocks import run_lockstep, run_realtime
from server.runs.commands import CommandError, EmergencyStop, RunCommand, Stop
from server.runs.core import RunCore
from server.runs.dialect import Dialect
from server.runs.outputs import ObserverSink, RunObserver, RunOutputs
from server.runs.recorder import Recorder
from server.runs.result import RunResult
from server.runs.slots import NodeSlot
from server.runs.spec import RunSpec, RunSpecError
from server.runs.state import RunState
from server.sim.backend import RobotBackend

__all__ = ["NodeSlot", "Run", "RunObserver"]


class Run:
    def __init__(
        self,
        spec: RunSpec,
        launcher: Launcher,
        out_dir: str | Path,
        run_id: str | None = None,
        observer: RunObserver | None = None,
        backend: RobotBackend | None = None,
    ) -> None:
        """`backend`: a real robot (server/hardware/backend.py); None: a `Simulation` of the
        spec's robot and world, made when the run starts."""
        spec.validate()
        if backend is not None and spec.clock is not Clock.REALTIME:
            raise RunSpecError("a run on a real robot needs the realtime clock")
        self.spec = spec
        self.launcher = launcher
        self.backend = backend
        self.run_id = run_id or uuid.uuid4().hex[:12]
        self.out_dir = Path(out_dir)
        self.outputs = RunOutputs()
        self._observer_sink: ObserverSink | None = None
        self.core = RunCore(spec, launcher, self.out_dir, self.run_id, self.outputs, backend)
        self.observer = observer

    @property
    def observer(self) -> RunObserver | None:
        return self._observer_sink.observer if self._observer_sink is not None else None

    @observer.setter
    def observer(self, observer: RunObserver | None) -> None:
        """Set before `execute()` (the service attaches its telemetry after making the run)."""
        if self._observer_sink is not None:
            self.outputs.remove(self._observer_sink)
            self._observer_sink = None
        if observer is not None:
            self._observer_sink = ObserverSink(observer, self.run_id)
            self.outputs.add(self._observer_sink)

    def execute(self) -> RunResult:
        """Run to the end and return the result. Never raises for anything a node does."""
        clock = run_lockstep if self.spec.clock is Clock.LOCKSTEP else run_realtime
        return self.core.run(clock)

    def command(self, command: RunCommand) -> None:
        """Take a command (server/runs/commands.py) from any thread; it is applied by the run's
        loop between two steps. Raises CommandError when the run's state refuses it now."""
        refusal = controls.refuse(self.core, command)
        if refusal is not None:
            raise CommandError(refusal)
        if isinstance(command, EmergencyStop) and self.backend is not None:
            self.backend.stop()  # a real robot stops now, from this thread, not at the next step
        self.core.inbox.put(command)

    def stop(self, reason: str = "stopped by the user") -> None:
        self.command(Stop(reason))

    # ----------------------------------------------------------------------------- read-only
    @property
    def state(self) -> RunState:
        return self.core.state

    @property
    def reason(self) -> str:
        return self.core.reason

    @property
    def time_ns(self) -> int:
        return self.core.time_ns

    @property
    def time_s(self) -> float:
        return self.core.time_s

    @property
    def progress(self) -> tuple[float, float]:
        """(run time [s], duration [s])."""
        return self.core.time_s, self.spec.duration_s

    def metrics(self) -> dict:
        return self.core.metrics()

    @property
    def slots(self) -> dict[str, NodeSlot]:
        return self.core.slots

    @property
    def bus(self) -> TopicBus:
        return self.core.bus

    @property
    def sim(self) -> RobotBackend | None:
        """The robot the run drives (the simulation, or `backend`); None before it starts."""
        return self.core.sim

    @property
    def dialect(self) -> Dialect:
        return self.core.dialect

    @property
    def builtins(self) -> BuiltinHost:
        return self.core.builtins

    @property
    def recorder(self) -> Recorder | None:
        return self.core.recorder
