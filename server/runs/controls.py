"""What the typed commands (server/runs/commands.py) do to a run: stop, pause/resume (lockstep),
the robot's button, a light, a goal pose, a key, a fault.

`refuse` runs on the sender's thread, when the command is given, and says why the run's state
refuses it now; `apply` runs on the run's own loop, between two steps, when the command is taken
from the run's inbox (server/runs/inbox.py), so the robot never sees two threads.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

from sandbox.protocol import Clock
from sandbox.units import NS_PER_S
from server.runs.commands import (
    Button,
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
    from server.runs.core import RunCore

log = logging.getLogger("robodojo.runs")


def refuse(core: RunCore, command: RunCommand) -> str | None:
    """Why `command` cannot be taken now, as a sentence; None when it can."""
    match command:
        case Pause() if core.spec.clock is not Clock.LOCKSTEP:
            return "only a lockstep (simulated-time) run can pause; stop it instead"
        case Pause() if core.state is RunState.PAUSED:
            return "the run is already paused; resume it to go on"
        case Resume() if core.state is not RunState.PAUSED:
            return f"the run is not paused (it is {core.state}); nothing to resume"
        case Teleop() if core.builtins.get("teleop") is None:
            return "this run takes no keyboard driving (its exercise has no teleop)"
    return None


def apply(core: RunCore, command: RunCommand) -> None:
    """Do what `command` says, on the run's loop. Stop raises RunEnd (the loop ends the run)."""
    match command:
        case Stop() | EmergencyStop():
            raise RunEnd(RunState.INTERRUPTED, f"interrupted: {command.reason}")
        case Pause() if core.state is RunState.RUNNING:
            core.move(RunState.PAUSED)
        case Resume() if core.state is RunState.PAUSED:
            core.move(RunState.RUNNING)
        case Button(pressed=pressed):
            core.sim.press_button(pressed)
        case Light(x=x, y=y, name=name):
            movable = [light.name for light in core.sim.lights if light.movable]
            try:
                if name is None and not movable:
                    raise SimulationError("this world has no light that can be moved")
                core.sim.move_light(name if name is not None else movable[0], x, y)
            except SimulationError as error:
                log.info("run %s: light not moved: %s", core.run_id, error)
        case Goal(x=x, y=y, yaw=yaw):
            core.edge.publish_goal(x, y, yaw, core.time_ns)
        case Teleop(key=key, pressed=pressed):
            teleop = core.builtins.get("teleop")
            if teleop is None:
                log.info("run %s: a teleop key, but the run has no teleop node", core.run_id)
            else:
                teleop.key(key, pressed)
        case InjectFault(kind=kind, topic=topic, duration_s=duration_s):
            core.faults.add(Fault(kind, topic, core.time_ns + round(duration_s * NS_PER_S)))
            if kind is FaultKind.STALL_MOTORS:
                core.edge.stall_motors()
