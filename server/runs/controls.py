"""Commands while a run runs (server/runs/commands.py): stop, pause/resume (lockstep), the
robot's button, a light, a goal pose, a key, a fault. Any thread may send them (the web
server's, the CLI's signal handler); they are queued and applied by the run's own loop between
two steps, so the simulation never sees two threads. A byte on a pipe wakes a realtime loop
that is sleeping until its next event.
"""

from __future__ import annotations

import contextlib
import logging
import os
import queue
from typing import TYPE_CHECKING

from sandbox.protocol import Clock
from server.runs.commands import (
    Button,
    CommandError,
    EmergencyStop,
    Goal,
    InjectFault,
    Light,
    Pause,
    Resume,
    RunCommand,
    Stop,
    Teleop,
)
from server.runs.faults import Fault, FaultKind
from server.runs.result import RunEnd
from server.runs.state import RunState
from server.sim.simulation import SimulationError

if TYPE_CHECKING:
    from server.runs.run import Run

log = logging.getLogger("robodojo.runs")
NS = 1_000_000_000


class RunControls:
    """Mixed into Run: the public control methods and how the loop applies them."""

    def __init__(self: Run) -> None:
        self._controls: queue.SimpleQueue = queue.SimpleQueue()
        self._control_signal_r, self._control_signal_w = os.pipe()
        os.set_blocking(self._control_signal_r, False)
        os.set_blocking(self._control_signal_w, False)

    def _close_controls(self: Run) -> None:
        for fd in (self._control_signal_r, self._control_signal_w):
            with contextlib.suppress(OSError):
                os.close(fd)

    def command(self, command: RunCommand) -> None:
        """Take a command (server/runs/commands.py) from any thread; it is applied by the run's
        loop between two steps. Raises CommandError when the run's state refuses it now."""
        if isinstance(command, Pause):
            if self.spec.clock is not Clock.LOCKSTEP:
                raise CommandError(
                    "only a lockstep (simulated-time) run can pause; stop it instead"
                )
            if self.state is RunState.PAUSED:
                raise CommandError("the run is already paused; resume it to go on")
        elif isinstance(command, Resume) and self.state is not RunState.PAUSED:
            raise CommandError(f"the run is not paused (it is {self.state}); nothing to resume")
        elif isinstance(command, Teleop) and self.builtins.get("teleop") is None:
            raise CommandError("this run takes no keyboard driving (its exercise has no teleop)")
        elif isinstance(command, EmergencyStop) and self.backend is not None:
            self.backend.stop()  # a real robot stops now, from this thread, not at the next step
        self._control(command)

    def stop(self, reason: str = "stopped by the user") -> None:
        self.command(Stop(reason))

    def _control(self, command: RunCommand) -> None:
        self._controls.put(command)
        # Wake a realtime loop that sleeps until its next event (see clocks.run_realtime).
        with contextlib.suppress(BlockingIOError, OSError):
            os.write(self._control_signal_w, b"!")

    @property
    def control_signal_fd(self) -> int:
        """Readable when a control is waiting: a sleeping loop can poll it."""
        return self._control_signal_r

    @property
    def progress(self) -> tuple[float, float]:
        """(run time [s], duration [s])."""
        return self.time_ns / NS, self.spec.duration_s

    def _apply_controls(self) -> None:
        if self._controls.empty():  # the common case, checked without a system call
            return
        with contextlib.suppress(BlockingIOError, OSError):
            os.read(self._control_signal_r, 4096)
        while True:
            try:
                command = self._controls.get_nowait()
            except queue.Empty:
                return
            self._apply_command(command)

    def _apply_command(self, command: RunCommand) -> None:
        match command:
            case Stop() | EmergencyStop():
                raise RunEnd(RunState.INTERRUPTED, f"interrupted: {command.reason}")
            case Pause() if self.state is RunState.RUNNING:
                self._move(RunState.PAUSED)
            case Resume() if self.state is RunState.PAUSED:
                self._move(RunState.RUNNING)
            case Button(pressed=pressed):
                self.sim.press_button(pressed)
            case Light(x=x, y=y, name=name):
                movable = [light.name for light in self.sim.lights if light.movable]
                try:
                    if name is None and not movable:
                        raise SimulationError("this world has no light that can be moved")
                    self.sim.move_light(name if name is not None else movable[0], x, y)
                except SimulationError as error:
                    log.info("run %s: light not moved: %s", self.run_id, error)
            case Goal(x=x, y=y, yaw=yaw):
                self._publish_goal(x, y, yaw)
            case Teleop(key=key, pressed=pressed):
                teleop = self.builtins.get("teleop")
                if teleop is None:
                    log.info("run %s: a teleop key, but the run has no teleop node", self.run_id)
                else:
                    teleop.key(key, pressed)
            case InjectFault(kind=kind, topic=topic, duration_s=duration_s):
                self.faults.add(Fault(kind, topic, self.time_ns + round(duration_s * NS)))
                if kind is FaultKind.STALL_MOTORS:
                    self._stall_motors()

    def wait_while_paused(self, timeout_s: float) -> None:
        """Block up to `timeout_s` for a control while paused (the loop calls this)."""
        try:
            command = self._controls.get(timeout=timeout_s)
        except queue.Empty:
            return
        self._apply_command(command)
