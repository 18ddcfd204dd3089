"""Controls while a run runs: stop, pause/resume (lockstep), the robot's button, a light, a goal
pose, a fault. Any thread may call them (the web server's, the CLI's signal handler); they are
queued and applied by the run's own loop between two steps, so the simulation never sees two
threads. A byte on a pipe wakes a realtime loop that is sleeping until its next event.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import queue
from typing import TYPE_CHECKING

from sandbox.protocol import Clock
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

    def stop(self, reason: str = "stopped by the user") -> None:
        self._control(("stop", reason))

    def pause(self) -> None:
        if self.spec.clock is not Clock.LOCKSTEP:
            raise ValueError("only a lockstep (simulated-time) run can pause; stop it instead")
        if self.state is RunState.PAUSED:
            raise ValueError("the run is already paused; resume it to go on")
        self._control(("pause", None))

    def resume(self) -> None:
        if self.state is not RunState.PAUSED:
            raise ValueError(f"the run is not paused (it is {self.state}); nothing to resume")
        self._control(("resume", None))

    def press_button(self, pressed: bool) -> None:
        self._control(("button", bool(pressed)))

    def move_light(self, name: str, x: float, y: float) -> None:
        self._control(("light", (name, float(x), float(y))))

    def set_goal(self, x: float, y: float, yaw: float = 0.0) -> None:
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise ValueError(f"a goal needs finite numbers, got ({x}, {y}, {yaw})")
        self._control(("goal", (float(x), float(y), float(yaw))))

    def inject_fault(self, kind: FaultKind | str, topic: str | None, duration_s: float) -> None:
        kind = FaultKind(kind)
        if kind is not FaultKind.STALL_MOTORS and not topic:
            raise ValueError(f"fault {kind} needs the topic it affects")
        if not (math.isfinite(duration_s) and duration_s > 0):
            raise ValueError(f"a fault lasts a positive number of seconds, got {duration_s}")
        self._control(("fault", (kind, topic, duration_s)))

    def teleop(self, key: str, pressed: bool) -> None:
        """An arrow key pressed or released in the browser (needs the `teleop` built-in)."""
        from server.runs.builtin import TELEOP_KEYS

        if key not in TELEOP_KEYS:
            raise ValueError(f"teleop knows the keys {', '.join(TELEOP_KEYS)}, not '{key}'")
        self._control(("teleop", (str(key), bool(pressed))))

    def _control(self, action: tuple[str, object]) -> None:
        self._controls.put(action)
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
                action, value = self._controls.get_nowait()
            except queue.Empty:
                return
            self._apply_control(action, value)

    def _apply_control(self, action: str, value: object) -> None:
        if action == "stop":
            raise RunEnd(RunState.INTERRUPTED, f"interrupted: {value}")
        if action == "pause" and self.state is RunState.RUNNING:
            self._move(RunState.PAUSED)
        elif action == "resume" and self.state is RunState.PAUSED:
            self._move(RunState.RUNNING)
        elif action == "button":
            self.sim.press_button(value)
        elif action == "light":
            name, x, y = value
            try:
                self.sim.move_light(name, x, y)
            except SimulationError as error:
                log.info("run %s: light not moved: %s", self.run_id, error)
        elif action == "goal":
            self._publish_goal(*value)
        elif action == "teleop":
            teleop = self.builtins.get("teleop")
            if teleop is None:
                log.info("run %s: a teleop key, but the run has no teleop node", self.run_id)
            else:
                teleop.key(*value)
        elif action == "fault":
            kind, topic, duration_s = value
            kind = FaultKind(kind)
            self.faults.add(Fault(kind, topic, self.time_ns + round(duration_s * NS)))
            if kind is FaultKind.STALL_MOTORS:
                self._stall_motors()

    def wait_while_paused(self, timeout_s: float) -> None:
        """Block up to `timeout_s` for a control while paused (the loop calls this)."""
        try:
            action, value = self._controls.get(timeout=timeout_s)
        except queue.Empty:
            return
        self._apply_control(action, value)
