"""`/api/runs/{id}/live`: one websocket per viewer of a run.

Server -> client frames (JSON):
    {"type": "snapshot", "run_id", "state", "reason", "time_s", "topics": {name: type}}
    {"type": "topic", "topic", "msg_type"}                      a topic's first message
    {"type": "telemetry", "topic", "msg_type", "time_s", "msg": {...}, "dropped": n,
     "wall_s"}                        wall_s: time.time() when the run produced the sample
    {"type": "log", "node", "line"} / {"type": "state", "state", "reason", "time_s"}
    {"type": "checks", "checks": [...], "score"}                                 exercises
    {"type": "dropped", "what": "events", "count": n}                            fell behind
    {"type": "ack", "id"} / {"type": "error", "id", "detail"}                    answers
    {"type": "end", "state", "reason"}                                           then close

Client -> server commands, each answered with an ack or an error carrying its "id" (one typed
message per op, dispatched from a table: server/api/live_ops.py):
    {"id": 1, "op": "subscribe", "topic": "Distance", "max_rate_hz": 20}
    {"op": "unsubscribe", "topic"} / {"op": "stop"} / {"op": "estop"} / {"op": "pause"}
    {"op": "resume"} / {"op": "button", "pressed": true} / {"op": "light", "x", "y", "name"?}
    {"op": "goal", "x", "y", "yaw"?} / {"op": "teleop", "key": "up", "pressed": true}
A stop's reason and an emergency stop's "who" come from the login, never from the frame.
Topics are named as the snapshot names them, root topics without the leading slash; a name as
`rostopic list` prints it ("/scan") is the same topic, and its frames say "scan".

Latest wins: a slow client gets the newest sample at its rate and a count of what it missed;
nothing queues per client beyond one frame in flight. Someone else's run: closed with code
4404, as if it did not exist; no login: 4401. A handshake from another site's page (its Origin
is not the lab's) is refused before accept (HTTP 403); a user disabled while watching is closed
with 1008.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import time

from fastapi import APIRouter, WebSocket, WebSocketDisconnect
from starlette.concurrency import run_in_threadpool

from server.api.auth import foreign_origin, websocket_user
from server.api.live_ops import LiveContext, apply_live
from server.api.sockets import still_valid
from server.runs.commands import CommandError
from server.service.telemetry import (
    KEEP_AFTER_END_S,
    SubscriptionError,
    UnknownRunError,
    ViewerLimitError,
)
from server.store import runs as run_store

router = APIRouter()
log = logging.getLogger("robodojo.api")
NOT_FOUND_CODE = 4404  # websocket close code: no such run, or not yours
NOT_LOGGED_IN_CODE = 4401  # websocket close code: no session cookie or token (as the 3D view)
COMMANDS_PER_S = 50  # a person clicking and typing; more is a runaway client
MAX_COMMAND_CHARS = 4096  # a command is a small JSON object
WAIT_S = 1.0  # [s] the writer wakes at least this often to notice a closed socket


@router.websocket("/api/runs/{run_id}/live")
async def live(websocket: WebSocket, run_id: str) -> None:
    app = websocket.app
    origin = foreign_origin(websocket.scope)
    if origin is not None:
        log.warning("run %s: live view refused: its page is at %s, not the lab's origin",
                    run_id[:64], origin)  # fmt: skip
        await websocket.close(code=1008)  # before accept: the handshake is answered 403
        return
    caller = await run_in_threadpool(websocket_user, websocket)
    record = None
    if caller is not None and len(run_id) <= 64:

        def lookup():
            with app.state.store.session() as db:
                return run_store.get(db, run_id)

        record = await run_in_threadpool(lookup)
    await websocket.accept()
    if caller is None:
        await websocket.close(code=NOT_LOGGED_IN_CODE, reason="not logged in")
        return
    if record is None or not caller.can_see(record.user_id):
        await websocket.close(code=NOT_FOUND_CODE, reason="no such run (or it is not yours)")
        return
    service = app.state.runs
    try:
        # In a cluster the first look may wait for Redis and the database: off the loop.
        telemetry = await run_in_threadpool(service.feed, run_id)
        if telemetry is None:
            raise UnknownRunError(
                f"run {run_id} has no live telemetry: it is not running or ended more than "
                f"{KEEP_AFTER_END_S:g} s ago; its recording has the data"
            )
        viewer = telemetry.viewer()
    except (UnknownRunError, ViewerLimitError) as error:
        # Ended long ago (or too many viewers): what the store knows, then the end.
        await websocket.send_json(
            {
                "type": "snapshot",
                "state": record.state,
                "reason": record.reason,
                "topics": {},
                "time_s": record.sim_time_s,
                "note": str(error),
            }
        )
        if record.checks:
            await websocket.send_json(
                {"type": "checks", "checks": record.checks, "score": record.score}
            )
        await websocket.send_json({"type": "end", "state": record.state, "reason": record.reason})
        await websocket.close()
        return
    context = LiveContext(caller, run_id, service, viewer)
    send_lock = asyncio.Lock()

    def recheck() -> bool:
        """The handshake's credential still names this caller (not logged out, renewed,
        expired or disabled since)."""
        again = websocket_user(websocket)
        return again is not None and again.id == caller.id

    async def send(frame: dict) -> None:
        async with send_lock:
            await websocket.send_text(json.dumps(frame, allow_nan=False, default=str))

    async def reader() -> None:
        window_start, count = time.monotonic(), 0
        while True:
            text = await websocket.receive_text()
            now = time.monotonic()
            if now - window_start >= 1.0:
                window_start, count = now, 0
            count += 1
            request_id = None
            try:
                if count > COMMANDS_PER_S:
                    raise CommandError(f"more than {COMMANDS_PER_S} commands a second; slow down")
                if len(text) > MAX_COMMAND_CHARS:
                    raise CommandError(f"a command is at most {MAX_COMMAND_CHARS} characters")
                try:
                    command = json.loads(text)
                except ValueError:
                    raise CommandError('a command is a JSON object, e.g. {"op": "stop"}') from None
                if not isinstance(command, dict):
                    raise CommandError('a command is a JSON object, e.g. {"op": "stop"}')
                request_id = command.get("id")
                if not isinstance(request_id, str | int | None) or isinstance(request_id, bool):
                    request_id = None
                    raise CommandError("'id' must be a string or an integer")
                if not await still_valid(recheck, revoked):
                    return  # the credential ended: nothing more is done for this socket
                await apply_live(command, context)
            except (CommandError, SubscriptionError, ValueError, TypeError) as error:
                await send({"type": "error", "id": request_id, "detail": str(error)})
            else:
                await send({"type": "ack", "id": request_id})

    async def writer() -> None:
        await send(telemetry.snapshot())
        while not viewer.finished:
            for frame in await viewer.next_frames(WAIT_S):
                await send(frame)
        final = telemetry.snapshot()
        await send({"type": "end", "state": final["state"], "reason": final["reason"]})

    close_code, close_reason = 1000, ""
    async with app.state.sockets.held(caller.id, recheck) as revoked:
        # Ended between the handshake's check and this registration: nothing is sent.
        valid = await still_valid(recheck, revoked)
        tasks = [asyncio.create_task(reader()), asyncio.create_task(writer())] if valid else []
        disabled = asyncio.create_task(revoked.wait())
        try:
            done, _ = await asyncio.wait([*tasks, disabled], return_when=asyncio.FIRST_COMPLETED)
            if revoked.is_set():
                close_code, close_reason = revoked.code, revoked.reason
            for task in done - {disabled}:
                error = task.exception()
                if error is not None and not isinstance(error, WebSocketDisconnect | RuntimeError):
                    raise error
        finally:
            for task in (*tasks, disabled):
                task.cancel()
            for task in (*tasks, disabled):
                with contextlib.suppress(BaseException):
                    await task
            viewer.close()
            with contextlib.suppress(Exception):
                await websocket.close(code=close_code, reason=close_reason)
