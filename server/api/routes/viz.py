"""A run's 3D view: viser's client page and websocket, proxied to the run's own ViserServer on a
loopback port (server/viz/manager.py), behind the same login and visibility as every run route.

    GET /api/runs/{id}/viz      -> redirect to .../viz/ (the client derives its websocket from
                                   its address: .../viz/ connects to .../viz)
    GET /api/runs/{id}/viz/     -> viser's client (index.html), bytes as viser sends them
    WS  /api/runs/{id}/viz      -> both directions forwarded to and from viser's websocket

Who: the session cookie (Path=/, so the browser sends it on the upgrade) or a Bearer token; the
run's owner or an instructor. Anyone else gets what a missing run gets: 404, or close code 4404
on the websocket; no login: 401, or close code 4401. A websocket from another site's page (its
Origin differs from the Host it asks) is refused at the handshake (403). The viser port itself
has no door of its own: it listens on 127.0.0.1 only and this proxy is the way in.

Websocket order (viser 1.1.1): the upstream socket is opened first with the subprotocol the
browser offered (`viser-v<version>`), then the browser's is accepted echoing the one viser
chose; without it viser closes 1002 and Chromium fails the handshake.
"""

from __future__ import annotations

import asyncio
import contextlib
import http.client
import logging
from contextlib import asynccontextmanager

from fastapi import APIRouter, Depends, Request, WebSocket
from fastapi.responses import RedirectResponse, Response
from starlette.concurrency import run_in_threadpool
from websockets.asyncio.client import connect
from websockets.exceptions import ConnectionClosed, InvalidHandshake

from server.api.auth import Caller, current_user, foreign_origin, websocket_user
from server.api.routes.runs import NOT_FOUND, file_answer, files_of, visible_run
from server.api.sockets import Revoked, still_valid
from server.store import runs as run_store
from server.viz.manager import LOOPBACK, VizManager

log = logging.getLogger("robodojo.api")
NOT_LOGGED_IN_CODE = 4401  # websocket close code: no session cookie or token
NOT_FOUND_CODE = 4404  # websocket close code: no such run, or not yours
UPSTREAM_TIMEOUT_S = 10.0  # [s] to reach the run's viser server on loopback
# Headers copied from viser's HTTP answer: the bytes go through untouched (gzip stays gzip).
PAGE_HEADERS = ("content-type", "content-encoding", "content-length")
# Close codes a server may not send (RFC 6455 7.4.1): reported as "going away" instead.
UNSENDABLE_CODES = frozenset({1005, 1006, 1015})


@asynccontextmanager
async def lifespan(app):
    app.state.viz = VizManager(app.state.runs)
    try:
        yield
    finally:
        await app.state.viz.close()


router = APIRouter(tags=["3d view"], lifespan=lifespan)


async def _session(request_or_socket, record):
    manager: VizManager = request_or_socket.app.state.viz
    return await manager.open(record.id, record.robot, record.world, record.run_dir)


def _fetch(port: int, path: str, accept_encoding: str) -> tuple[int, list[tuple[str, str]], bytes]:
    connection = http.client.HTTPConnection(LOOPBACK, port, timeout=UPSTREAM_TIMEOUT_S)
    try:
        connection.request("GET", path, headers={"Accept-Encoding": accept_encoding})
        answer = connection.getresponse()
        return answer.status, answer.getheaders(), answer.read()
    finally:
        connection.close()


@router.get("/api/runs/{run_id}/viz", include_in_schema=False)
def view_redirect(run_id: str, request: Request, caller: Caller = Depends(current_user)):
    visible_run(request, caller, run_id)
    query = f"?{request.url.query}" if request.url.query else ""
    # Relative, so it holds behind a proxy that mounts the lab under a prefix.
    return RedirectResponse(f"viz/{query}", status_code=307)


@router.get(
    "/api/runs/{run_id}/viz/{asset:path}",
    summary="The run's 3D view (viser's client page; its websocket is the same path without /)",
    response_class=Response,
    responses=file_answer("*/*"),  # viser's page, scripts, styles and images
)
async def view_page(
    run_id: str, asset: str, request: Request, caller: Caller = Depends(current_user)
) -> Response:
    record = await run_in_threadpool(files_of, request, caller, run_id)
    session = await _session(request, record)
    status, headers, body = await run_in_threadpool(
        _fetch, session.port, "/" + asset, request.headers.get("accept-encoding", "")
    )
    kept = {name: value for name, value in headers if name.lower() in PAGE_HEADERS}
    kept.update(
        {
            "Cache-Control": "no-cache",  # the client must match the server's viser version
            "X-Content-Type-Options": "nosniff",
            # A click in the view sets the robot's goal: no other site may frame it.
            "Content-Security-Policy": "frame-ancestors 'self'",
            "Referrer-Policy": "no-referrer",
        }
    )
    return Response(body, status_code=status, headers=kept)


async def _visible_record(websocket: WebSocket, run_id: str):
    """(record, caller, None) for a caller who may see the run, else (None, None, (close code,
    reason))."""
    caller = await run_in_threadpool(websocket_user, websocket)
    if caller is None:
        return None, None, (NOT_LOGGED_IN_CODE, "not logged in")
    record = None
    if len(run_id) <= 64 and "\x00" not in run_id:

        def lookup():
            with websocket.app.state.store.session() as db:
                return run_store.get(db, run_id)

        record = await run_in_threadpool(lookup)
    if record is None or not caller.can_see(record.user_id):
        return None, None, (NOT_FOUND_CODE, NOT_FOUND)
    return record, caller, None


@router.websocket("/api/runs/{run_id}/viz")
async def view_socket(websocket: WebSocket, run_id: str) -> None:
    origin = foreign_origin(websocket.scope)
    if origin is not None:
        log.warning("run %s: 3D view refused: its page is at %s, not the lab's origin",
                    run_id[:64], origin)  # fmt: skip
        await websocket.close(code=1008)  # before accept: the handshake is answered 403
        return
    record, caller, refusal = await _visible_record(websocket, run_id)
    if refusal is not None:
        await websocket.accept()
        await websocket.close(code=refusal[0], reason=refusal[1])
        return
    manager: VizManager = websocket.app.state.viz
    session = await _session(websocket, record)
    offered = [p for p in websocket.scope.get("subprotocols", []) if p.startswith("viser-v")]
    async with manager.watching(session):
        try:
            upstream = await connect(
                f"ws://{LOOPBACK}:{session.port}/",
                subprotocols=offered or None,
                max_size=None,  # a point cloud or mesh can be many MB (the default is 1 MiB)
                compression=None,  # viser does not compress per message; deflate costs time
                open_timeout=UPSTREAM_TIMEOUT_S,
                ping_interval=None,  # loopback: a dead peer shows as a closed socket
            )
        except (OSError, InvalidHandshake, TimeoutError):
            await websocket.accept()
            await websocket.close(code=1011, reason="the 3D view is not available; reload")
            return
        async with upstream:
            await websocket.accept(subprotocol=upstream.subprotocol)

            def recheck() -> bool:
                """The handshake's credential still names this caller."""
                again = websocket_user(websocket)
                return again is not None and again.id == caller.id

            async with websocket.app.state.sockets.held(caller.id, recheck) as revoked:
                if await still_valid(recheck, revoked):
                    await _pump(websocket, upstream, revoked)
                else:  # ended between the handshake and now: nothing is forwarded
                    with contextlib.suppress(Exception):
                        await websocket.close(code=revoked.code, reason=revoked.reason)


async def _pump(websocket: WebSocket, upstream, revoked: Revoked) -> None:
    """Forward both ways until either side closes; then close the other with the same code.
    `revoked` set (the user was disabled, or the credential ended): both close, the browser
    with revoked's code and reason."""

    async def browser_to_viser() -> tuple[int, str]:
        while True:
            message = await websocket.receive()
            if message["type"] == "websocket.disconnect":
                return message.get("code", 1000), ""
            data = message.get("bytes")
            await upstream.send(data if data is not None else message.get("text", ""))

    async def viser_to_browser() -> tuple[int, str]:
        with contextlib.suppress(ConnectionClosed):
            async for data in upstream:
                if isinstance(data, bytes):
                    await websocket.send_bytes(data)
                else:
                    await websocket.send_text(data)
        return upstream.close_code or 1000, upstream.close_reason or ""

    to_viser = asyncio.create_task(browser_to_viser())
    to_browser = asyncio.create_task(viser_to_browser())
    disabled = asyncio.create_task(revoked.wait())
    try:
        await asyncio.wait((to_viser, to_browser, disabled), return_when=asyncio.FIRST_COMPLETED)
    finally:
        for task in (to_viser, to_browser, disabled):
            task.cancel()
        for task in (to_viser, to_browser, disabled):
            with contextlib.suppress(BaseException):
                await task
    code, reason = 1000, ""
    if revoked.is_set():
        code, reason = revoked.code, revoked.reason
    elif to_browser.done() and not to_browser.cancelled() and to_browser.exception() is None:
        code, reason = to_browser.result()  # viser closed: the browser hears why
    with contextlib.suppress(Exception):
        await upstream.close()
    with contextlib.suppress(Exception):  # already gone if the browser closed first
        await websocket.close(code=1001 if code in UNSENDABLE_CODES else code, reason=reason)
