"""Every open websocket (live telemetry, 3D view) by its user, so that disabling a user ends
them: a disabled user's sessions end in the store, and their sockets, which were authenticated
once at the handshake, close here too (issue 14, finding 6).

    async with app.state.sockets.held(caller.id) as revoked:   # in a websocket route
        ... wait on `revoked` (an asyncio.Event) next to the socket's own work ...
    app.state.sockets.revoke(user_id)                           # any thread (the admin route)
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
from collections.abc import AsyncIterator

REVOKED_CODE = 1008  # websocket close code (policy violation): the account was disabled
REVOKED_REASON = "your account was disabled"


class OpenSockets:
    def __init__(self) -> None:
        self._lock = threading.Lock()  # the admin route runs in a worker thread
        self._held: dict[str, set[tuple[asyncio.AbstractEventLoop, asyncio.Event]]] = {}

    @contextlib.asynccontextmanager
    async def held(self, user_id: str) -> AsyncIterator[asyncio.Event]:
        """An event set when `user_id` is disabled while this socket is open."""
        entry = (asyncio.get_running_loop(), asyncio.Event())
        with self._lock:
            self._held.setdefault(user_id, set()).add(entry)
        try:
            yield entry[1]
        finally:
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
                loop.call_soon_threadsafe(event.set)
        return len(entries)
