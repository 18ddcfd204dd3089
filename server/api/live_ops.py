"""What a viewer may send on a run's live websocket (server/api/routes/live.py), one typed message
per op, and the table that says what each does.

    {"id": 1, "op": "subscribe", "topic": "Distance", "max_rate_hz": 20}   -> Subscribe
    {"op": "unsubscribe", "topic": "Distance"}                               -> Unsubscribe
    {"op": "stop"} / {"op": "estop"}                -> Stop / EmergencyStop named after the caller
    {"op": "pause"} / {"op": "resume"} / {"op": "button", "pressed": true}
    {"op": "light", "x", "y", "name"?} / {"op": "goal", "x", "y", "yaw"?}
    {"op": "teleop", "key": "up", "pressed": true}  -> the run command itself (commands.py)

Who stops a run is the login's to say: "stop" and "estop" take no fields, and the Stop or
EmergencyStop sent to the run is made from the caller ("emergency stop by the user"), so a
student cannot write {"op": "estop", "who": "the instructor"}. A fault is not a viewer's to
inject (exercises script them). Every message is parsed with `parse_fields`, so an unknown key
is refused with a sentence, as in the run commands.
"""

from __future__ import annotations

from collections.abc import Awaitable, Callable, Mapping
from dataclasses import dataclass
from typing import ClassVar

from starlette.concurrency import run_in_threadpool

from server.api.auth import Caller
from server.api.routes.runs import emergency_stop_by, stop_by
from server.runs.commands import (
    Button,
    CommandError,
    Goal,
    Light,
    Pause,
    Resume,
    RunCommand,
    Teleop,
    parse_fields,
)
from server.service.runs import RunService
from server.service.telemetry import Viewer

DEFAULT_RATE_HZ = 10.0  # [Hz] a subscription that names no rate


@dataclass(frozen=True, slots=True)
class Subscribe:
    """Send this topic's newest sample at most `max_rate_hz` times a second (the viewer checks
    the topic and the rate and says what is wrong)."""

    op: ClassVar[str] = "subscribe"
    topic: str
    max_rate_hz: float = DEFAULT_RATE_HZ


@dataclass(frozen=True, slots=True)
class Unsubscribe:
    """Send no more of this topic."""

    op: ClassVar[str] = "unsubscribe"
    topic: str


@dataclass(frozen=True, slots=True)
class StopRequest:
    """Stop the run; the reason says who, from the login ("stopped by the user")."""

    op: ClassVar[str] = "stop"


@dataclass(frozen=True, slots=True)
class EmergencyStopRequest:
    """Stop the run and, on a real robot, zero velocity at once; named after the login."""

    op: ClassVar[str] = "estop"


@dataclass(frozen=True, slots=True)
class LiveContext:
    """Who sends, to which run, through which viewer: what a handler may use."""

    caller: Caller
    run_id: str
    service: RunService
    viewer: Viewer

    async def tell_run(self, command: RunCommand) -> None:
        """Send a command through the service; off the event loop, since an emergency stop
        writes to a robot's link from the calling thread."""
        running = await run_in_threadpool(self.service.command, self.run_id, command)
        if not running:
            raise CommandError(f"the run has ended; '{command.op}' needs a running run")


Handler = Callable[[object, LiveContext], Awaitable[None]]


async def _subscribe(message: Subscribe, context: LiveContext) -> None:
    context.viewer.subscribe(message.topic, message.max_rate_hz)


async def _unsubscribe(message: Unsubscribe, context: LiveContext) -> None:
    context.viewer.unsubscribe(message.topic)


async def _stop(_: StopRequest, context: LiveContext) -> None:
    await context.tell_run(stop_by(context.caller))


async def _emergency_stop(_: EmergencyStopRequest, context: LiveContext) -> None:
    await context.tell_run(emergency_stop_by(context.caller))


async def _forward(command: RunCommand, context: LiveContext) -> None:
    await context.tell_run(command)


# op -> (its message type, what it does)
LIVE_OPS: dict[str, tuple[type, Handler]] = {
    Subscribe.op: (Subscribe, _subscribe),
    Unsubscribe.op: (Unsubscribe, _unsubscribe),
    StopRequest.op: (StopRequest, _stop),
    EmergencyStopRequest.op: (EmergencyStopRequest, _emergency_stop),
    **{cls.op: (cls, _forward) for cls in (Pause, Resume, Button, Light, Goal, Teleop)},
}


def parse_live(frame: Mapping[str, object]) -> tuple[object, Handler]:
    """The typed message a websocket frame (a JSON object) holds and its handler; CommandError
    with a sentence when it holds none. The frame's "id" is the request's, not the message's."""
    op = frame.get("op")
    entry = LIVE_OPS.get(op) if isinstance(op, str) else None
    if entry is None:
        raise CommandError(f"unknown op {op!r}; ops: {', '.join(LIVE_OPS)}")
    cls, handler = entry
    return parse_fields(cls, frame), handler


async def apply_live(frame: Mapping[str, object], context: LiveContext) -> None:
    """Do what a frame asks; raises CommandError (or the viewer's SubscriptionError) with a
    sentence when it cannot be done."""
    message, handler = parse_live(frame)
    await handler(message, context)
