"""What a running run can be told, one small frozen dataclass per command.

    run.command(Button(pressed=True))                     # any thread; applied between two steps
    service.command(run_id, Goal(x=1.0, y=0.5), who)      # the one door for routes and sockets
    parse_command({"op": "light", "x": 1.5, "y": 1.0})    # a websocket frame, a script, JSON
    command_dict(Goal(1.0, 0.5))  ->  {"op": "goal", "x": 1.0, "y": 0.5, "yaw": 0.0}

Every way into a run speaks these: an exercise's scripted events, the live websocket, the HTTP
routes, the 3D view's clicks, the hardware hub's end of a time slot. They are plain data (what
`command_dict` gives round-trips through JSON and `parse_command`), so a command can cross a
process boundary as it is. Each checks its own values when made and says what is wrong in a
sentence (`CommandError`); what depends on the run's state (pausing a realtime run) is checked by
the run when it receives the command.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import ClassVar, TypeVar

from server.runs.faults import FaultKind

TELEOP_KEYS = ("up", "down", "left", "right")  # the arrow keys the teleop built-in knows
MAX_REASON_CHARS = 500  # a stop reason is a sentence, not a document


class CommandError(ValueError):
    """A command that cannot be made as given; the message says what to send instead."""


def _finite(op: str, name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise CommandError(f"'{name}' must be a finite number for '{op}', got {value!r}")
    return float(value)


def _flag(op: str, name: str, value: object) -> bool:
    if not isinstance(value, bool):
        raise CommandError(f"'{name}' must be true or false for '{op}', got {value!r}")
    return value


def _text(op: str, name: str, value: object, limit: int = MAX_REASON_CHARS) -> str:
    if not isinstance(value, str) or len(value) > limit:
        raise CommandError(f"'{name}' must be text of at most {limit} characters for '{op}'")
    return value


@dataclass(frozen=True, slots=True)
class Stop:
    """End the run now ("interrupted: <reason>"); the robot is commanded to zero."""

    op: ClassVar[str] = "stop"
    reason: str = "stopped by the user"

    def __post_init__(self) -> None:
        _text(self.op, "reason", self.reason)


@dataclass(frozen=True, slots=True)
class EmergencyStop:
    """Stop, and on a real robot send zero velocity from the caller's thread at once, without
    waiting for the run's loop."""

    op: ClassVar[str] = "estop"
    who: str = "the user"

    def __post_init__(self) -> None:
        _text(self.op, "who", self.who)

    @property
    def reason(self) -> str:
        return f"emergency stop by {self.who}"


@dataclass(frozen=True, slots=True)
class Pause:
    """Hold a lockstep run's simulated time (a realtime run cannot pause)."""

    op: ClassVar[str] = "pause"


@dataclass(frozen=True, slots=True)
class Resume:
    op: ClassVar[str] = "resume"


@dataclass(frozen=True, slots=True)
class Button:
    """Press or release the robot's push button."""

    op: ClassVar[str] = "button"
    pressed: bool = True

    def __post_init__(self) -> None:
        _flag(self.op, "pressed", self.pressed)


@dataclass(frozen=True, slots=True)
class Light:
    """Move a light of the world to (x, y) [m]; name None: the world's first movable light."""

    op: ClassVar[str] = "light"
    x: float
    y: float
    name: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "x", _finite(self.op, "x", self.x))
        object.__setattr__(self, "y", _finite(self.op, "y", self.y))
        if self.name is not None:
            _text(self.op, "name", self.name, 100)


@dataclass(frozen=True, slots=True)
class Goal:
    """Publish a goal pose (x, y [m], yaw [rad]) on the run's "goal" topic."""

    op: ClassVar[str] = "goal"
    x: float
    y: float
    yaw: float = 0.0

    def __post_init__(self) -> None:
        for name in ("x", "y", "yaw"):
            object.__setattr__(self, name, _finite(self.op, name, getattr(self, name)))


@dataclass(frozen=True, slots=True)
class Teleop:
    """An arrow key pressed or released in the browser (needs the teleop built-in)."""

    op: ClassVar[str] = "teleop"
    key: str
    pressed: bool = True

    def __post_init__(self) -> None:
        if self.key not in TELEOP_KEYS:
            raise CommandError(f"teleop knows the keys {', '.join(TELEOP_KEYS)}, not {self.key!r}")
        _flag(self.op, "pressed", self.pressed)


@dataclass(frozen=True, slots=True)
class InjectFault:
    """A fault that lasts `duration_s` [s]: a topic dropped or frozen, or the motors stalled."""

    op: ClassVar[str] = "fault"
    kind: FaultKind
    topic: str | None = None
    duration_s: float = 1.0

    def __post_init__(self) -> None:
        try:
            object.__setattr__(self, "kind", FaultKind(self.kind))
        except ValueError:
            kinds = ", ".join(str(kind) for kind in FaultKind)
            raise CommandError(f"a fault is one of {kinds}, not {self.kind!r}") from None
        if self.kind is not FaultKind.STALL_MOTORS and not self.topic:
            raise CommandError(f"fault {self.kind} needs the topic it affects")
        if self.topic is not None:
            _text(self.op, "topic", self.topic, 200)
        duration = _finite(self.op, "duration_s", self.duration_s)
        if duration <= 0:
            raise CommandError(f"a fault lasts a positive number of seconds, got {duration:g}")
        object.__setattr__(self, "duration_s", duration)


RunCommand = Stop | EmergencyStop | Pause | Resume | Button | Light | Goal | Teleop | InjectFault

COMMANDS: dict[str, type[RunCommand]] = {
    cls.op: cls
    for cls in (Stop, EmergencyStop, Pause, Resume, Button, Light, Goal, Teleop, InjectFault)
}
# What an exercise's script may do at a time of its choosing (stopping is the run's duration).
SCRIPTABLE: tuple[type[RunCommand], ...] = (Button, Light, Goal, Teleop, InjectFault)


Message = TypeVar("Message")  # a frozen dataclass with an `op` ClassVar, as the commands above


def command_dict(command: RunCommand) -> dict[str, object]:
    """The command as plain JSON-ready data: {"op": ..., field: value, ...}."""
    fields = {f.name: getattr(command, f.name) for f in dataclasses.fields(command)}
    if isinstance(command, InjectFault):
        fields["kind"] = str(command.kind)
    return {"op": command.op, **fields}


def parse_command(data: Mapping[str, object], ignore: tuple[str, ...] = ("id",)) -> RunCommand:
    """The command a JSON object describes; CommandError with a sentence when it describes none.
    Keys in `ignore` (a websocket frame's request id) are not the command's."""
    if not isinstance(data, Mapping):
        raise CommandError('a command is a JSON object, e.g. {"op": "stop"}')
    op = data.get("op")
    cls = COMMANDS.get(op) if isinstance(op, str) else None
    if cls is None:
        raise CommandError(f"unknown op {op!r}; ops: {', '.join(COMMANDS)}")
    return parse_fields(cls, data, ignore)


def parse_fields(
    cls: type[Message], data: Mapping[str, object], ignore: tuple[str, ...] = ("id",)
) -> Message:
    """`data` (a JSON object naming `cls.op`) as the frozen dataclass `cls`: unknown keys and
    missing fields are refused with a sentence (CommandError), the values checked by `cls`.
    Other typed messages (the live websocket's) are parsed with it too."""
    op = cls.op
    names = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(str(key) for key in data if key not in names and key not in ("op", *ignore))
    if unknown:
        accepted = ", ".join(sorted(names)) or "no fields"
        raise CommandError(f"'{op}' takes {accepted}; it does not know {', '.join(unknown)}")
    missing = [
        f.name
        for f in dataclasses.fields(cls)
        if f.name not in data
        and f.default is dataclasses.MISSING
        and f.default_factory is dataclasses.MISSING
    ]
    if missing:
        raise CommandError(f"'{op}' needs {', '.join(missing)}")
    return cls(**{key: value for key, value in data.items() if key in names})
