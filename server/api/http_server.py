"""How `robodojo serve` runs uvicorn safely: a bound on the time a client may take to send a
request's headers (here), and no secret in any log line (server/api/redaction.py).

Header timeout: uvicorn closes idle keep-alive connections (`timeout_keep_alive`) but sets no
timer between a connection's first byte and the end of its headers, so a client that sends a
request line and never finishes holds its connection forever (slowloris; 150 such connections
stayed open after 20 s). `h11_with_header_timeout` gives uvicorn's h11 protocol a timer, armed
when a connection opens and again when a response completes, that closes the connection if the
next request's headers are not complete when it fires (nginx's client_header_timeout, the same
idea). The h11 parser also bounds the headers' size (`h11_max_incomplete_event_size`).
"""

from __future__ import annotations

import asyncio
from typing import Any

import h11
from uvicorn.protocols.http.h11_impl import H11Protocol


def h11_with_header_timeout(header_timeout_s: float) -> type[H11Protocol]:
    """uvicorn's h11 protocol, closing a connection whose request headers take longer than
    `header_timeout_s` [s] (counted from the connection, or from the previous response)."""

    class HeaderTimeoutH11Protocol(H11Protocol):
        _header_timer: asyncio.TimerHandle | None = None

        def _arm_header_timer(self) -> None:
            self._cancel_header_timer()
            self._header_timer = self.loop.call_later(header_timeout_s, self._headers_too_slow)

        def _cancel_header_timer(self) -> None:
            if self._header_timer is not None:
                self._header_timer.cancel()
                self._header_timer = None

        def _headers_too_slow(self) -> None:
            self._header_timer = None
            # IDLE: h11 has not yet parsed a whole request line and headers on this connection.
            if self.conn.their_state is h11.IDLE and not self.transport.is_closing():
                self.transport.close()

        def connection_made(self, transport: Any) -> None:  # type: ignore[override]
            super().connection_made(transport)
            self._arm_header_timer()

        def on_response_complete(self) -> None:
            super().on_response_complete()
            if not self.transport.is_closing():
                self._arm_header_timer()

        def connection_lost(self, exc: Exception | None) -> None:
            self._cancel_header_timer()
            super().connection_lost(exc)

    return HeaderTimeoutH11Protocol
