"""Every open websocket (live telemetry, 3D view) by its user, and what ends one before its
peer does: a socket is authenticated once at the handshake, so the credential it was opened
with (a session cookie or a token) is checked again while it is open.

- Disabling a user ends their sessions in the store and, here, tells each of their sockets at
  once (issue 14, finding 6): `revoke(user_id)`, from any thread.
- Logout, token renewal and a session's expiry end the credential in the store (in whichever
  web process answered); every socket re-checks its own credential every `RECHECK_S`, so it
  closes within that (plus one query) in every process of a cluster (issue 33, finding 11).
- A socket's route checks the credential again before it acts on a command (`still_valid`),
  so a command never runs with a credential that ended, even within `RECHECK_S`.

    async with app.state.sockets.held(caller.id, recheck) as revoked:   # in a websocket route
        ... wait on `revoked` (an asyncio.Event) next to the socket's own work; when it is set,
        close with revoked.code and revoked.reason ...
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
from collections.abc import AsyncIterator, Callable

from starlette.concurrency import run_in_threadpool

REVOKED_CODE = 1008  # websocket close code (policy violation): the account was disabled
REVOKED_REASON = "your account was disabled"
ENDED_CODE = 4401  # the handshake's "not logged in": the credential is no longer valid
ENDED_REASON = "your session ended (logged out, its login link renewed, or expired): log in again"
RECHECK_S = 0.5  # [s] between two checks of an open socket's credential: one indexed query each


class Revoked(asyncio.Event):
    """Set when the socket must close; says with which code and reason."""

    code: int = REVOKED_CODE
    reason: str = REVOKED_REASON

    def end(self, code: int, reason: str) -> None:
        if not self.is_set():
            self.code, self.reason = code, reason
            self.set()


class OpenSockets:
    def __init__(self) -> None:
        self._lock = threading.Lock()  # the admin route runs in a worker thread
        self._held: dict[str, set[tuple[asyncio.AbstractEventLoop, Revoked]]] = {}

    @contextlib.asynccontextmanager
    async def held(
        self, user_id: str, recheck: Callable[[], bool] | None = None
    ) -> AsyncIterator[Revoked]:
        """An event set when `user_id` is disabled while this socket is open, or, given
        `recheck` (blocking: it runs in a worker thread; true while the socket's credential is
        valid), when that credential ends."""
        entry = (asyncio.get_running_loop(), Revoked())
        with self._lock:
            self._held.setdefault(user_id, set()).add(entry)
        watcher = asyncio.create_task(_watch(recheck, entry[1])) if recheck else None
        try:
            yield entry[1]
        finally:
            if watcher is not None:
                watcher.cancel()
                with contextlib.suppress(BaseException):
                    await watcher
            with self._lock:
                entries = self._held.get(user_id, set())
                entries.discard(entry)
                if not entries:
                    self._held.pop(user_id, None)

    def revoke(self, user_id: str) -> int:
        """Tell every open socket of `user_id` to close; returns how many were open."""
        with self._lock:
            entries = list(self._held.get(user_id, ()))
        for loop, event in entries:
            with contextlib.suppress(RuntimeError):  # the loop has closed: nothing to end
                loop.call_soon_threadsafe(event.end, REVOKED_CODE, REVOKED_REASON)
        return len(entries)


async def still_valid(recheck: Callable[[], bool], revoked: Revoked) -> bool:
    """Check the credential now (before acting on a command); False, with `revoked` set, when
    it ended."""
    if revoked.is_set():
        return False
    if await run_in_threadpool(recheck):
        return True
    revoked.end(ENDED_CODE, ENDED_REASON)
    return False


async def _watch(recheck: Callable[[], bool], revoked: Revoked) -> None:
    # The route checks once before its socket does anything (still_valid); then every RECHECK_S.
    while not revoked.is_set():
        await asyncio.sleep(RECHECK_S)
        if not await still_valid(recheck, revoked):
            return
