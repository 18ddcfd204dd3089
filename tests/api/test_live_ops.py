"""The live websocket's typed messages (server/api/live_ops.py), without a server: each op goes to
its handler, run commands reach the service typed, and who stops a run is the login's to say,
never the frame's."""

from __future__ import annotations

import asyncio

import pytest

from server.api.auth import Caller
from server.api.live_ops import DEFAULT_RATE_HZ, LIVE_OPS, LiveContext, apply_live, parse_live
from server.runs.commands import (
    Button,
    CommandError,
    EmergencyStop,
    Goal,
    Light,
    Pause,
    Resume,
    Stop,
    Teleop,
)
from server.service.telemetry import RunTelemetry
from server.store.accounts import Role

STUDENT = Caller("s1", "ada", Role.STUDENT)
INSTRUCTOR = Caller("i1", "grace", Role.INSTRUCTOR)


class SentToService:
    """RunService.command for one run that is going (or has ended)."""

    def __init__(self, running: bool = True) -> None:
        self.running = running
        self.sent: list[tuple[str, object]] = []

    def command(self, run_id: str, command) -> bool:
        self.sent.append((run_id, command))
        return self.running


def apply(frame: dict, caller: Caller = STUDENT, service=None) -> list:
    """Apply one frame as the websocket would (a viewer lives on the socket's loop)."""
    service = service or SentToService()

    async def main() -> None:
        viewer = RunTelemetry("r1").viewer()
        try:
            await apply_live(frame, LiveContext(caller, "r1", service, viewer))
        finally:
            viewer.close()

    asyncio.run(main())
    return service.sent


def test_the_table_holds_the_ops_the_page_sends_and_no_fault():
    # web/src: subscribe/unsubscribe (common/live.js), estop (student/estop.js), button, goal,
    # light (student/world.js), teleop (student/teleop.js); stop/pause/resume for other clients.
    assert set(LIVE_OPS) == {"subscribe", "unsubscribe", "stop", "estop", "pause", "resume",
                             "button", "light", "goal", "teleop"}  # fmt: skip
    with pytest.raises(CommandError, match="unknown op 'fault'"):
        parse_live({"op": "fault", "kind": "stall_motors"})


@pytest.mark.parametrize(
    ("frame", "command"),
    [
        ({"id": 1, "op": "button", "pressed": True}, Button(True)),
        ({"id": "l", "op": "light", "name": "lamp", "x": 0.5, "y": -0.5}, Light(0.5, -0.5, "lamp")),
        ({"op": "goal", "x": 0.2, "y": 0.1, "yaw": 1.0}, Goal(0.2, 0.1, 1.0)),
        ({"op": "teleop", "key": "up", "pressed": False}, Teleop("up", False)),
        ({"op": "pause"}, Pause()),
        ({"op": "resume"}, Resume()),
    ],
)
def test_run_commands_reach_the_service_typed(frame, command):
    assert apply(frame) == [("r1", command)]


def test_a_stop_is_named_after_the_login():
    assert apply({"op": "stop"}) == [("r1", Stop("stopped by the user"))]
    assert apply({"op": "stop"}, INSTRUCTOR) == [("r1", Stop("stopped by an instructor"))]
    assert apply({"op": "estop"}) == [("r1", EmergencyStop("the user"))]
    assert apply({"op": "estop"}, INSTRUCTOR) == [("r1", EmergencyStop("an instructor"))]


@pytest.mark.parametrize(
    "frame",
    [
        {"op": "estop", "who": "the instructor"},
        {"op": "stop", "reason": "stopped by an instructor"},
        {"op": "stop", "who": "an instructor"},
    ],
)
def test_a_student_cannot_say_who_stopped(frame):
    service = SentToService()
    with pytest.raises(CommandError, match="takes no fields; it does not know"):
        apply(frame, STUDENT, service)
    assert service.sent == []  # nothing reached the run


def test_a_command_to_an_ended_run_says_so():
    with pytest.raises(CommandError, match="the run has ended; 'goal' needs a running run"):
        apply({"op": "goal", "x": 0, "y": 0}, service=SentToService(running=False))


def test_subscribe_goes_to_the_viewer_with_its_rate():
    service = SentToService()

    async def main() -> None:
        viewer = RunTelemetry("r1").viewer()
        context = LiveContext(STUDENT, "r1", service, viewer)
        await apply_live({"id": 3, "op": "subscribe", "topic": "Light", "max_rate_hz": 4}, context)
        await apply_live({"op": "subscribe", "topic": "Distance"}, context)
        assert viewer.subscriptions == {"Light": 4.0, "Distance": DEFAULT_RATE_HZ}
        await apply_live({"op": "unsubscribe", "topic": "Light"}, context)
        assert set(viewer.subscriptions) == {"Distance"}
        viewer.close()

    asyncio.run(main())
    assert service.sent == []  # a viewer's op is not the run's
    with pytest.raises(CommandError, match="'subscribe' needs topic"):
        parse_live({"op": "subscribe"})
    with pytest.raises(CommandError, match="it does not know rate"):
        parse_live({"op": "subscribe", "topic": "Light", "rate": 4})
