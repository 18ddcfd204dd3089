"""How `robodojo serve` runs uvicorn safely: bounds on the time a client may take to send a
request's headers and its body (here), and no secret in any log line (server/api/redaction.py).

Header timeout: uvicorn closes idle keep-alive connections (`timeout_keep_alive`) but sets no
timer between a connection's first byte and the end of its headers, so a client that sends a
request line and never finishes holds its connection forever (slowloris; 150 such connections
stayed open after 20 s). `h11_with_timeouts` gives uvicorn's h11 protocol a timer, armed when a
connection opens and again when a response completes, that closes the connection if the next
request's headers are not complete when it fires (nginx's client_header_timeout, the same
idea). The h11 parser also bounds the headers' size (`h11_max_incomplete_event_size`).

Body timeout: nor is there a timer while a body arrives, and every byte a client sends cancels
the keep-alive timer, so 50 connections sending a login body 1 byte every 4 s stayed open past
72 s (issue 33), before any route or login check could refuse them. A second timer runs from
the end of a request's headers until its body is whole, moved on as bytes arrive, as
`BodyPace` allows (server/api/http_guards.py: whole within a timeout, at a minimum rate after a
grace). When it fires, a request not yet answered gets 408 with a sentence and the connection
is closed; one already answered (a route that did not read the body) is closed. The app, if it
is still waiting for the body, is told the client left, so it answers nothing more.
"""

from __future__ import annotations

import asyncio
import json
from typing import Any

import h11
from uvicorn.protocols.http.h11_impl import H11Protocol

from server.api.http_guards import SECURITY_HEADERS, BodyPace


def h11_with_timeouts(header_timeout_s: float, body_pace: BodyPace) -> type[H11Protocol]:
    """uvicorn's h11 protocol, closing a connection whose request headers take longer than
    `header_timeout_s` [s] (counted from the connection, or from the previous response), and
    answering 408 to a request whose body comes slower than `body_pace` allows."""

    class TimedH11Protocol(H11Protocol):
        _header_timer: asyncio.TimerHandle | None = None
        _body_timer: asyncio.TimerHandle | None = None
        _body_started_s: float | None = None  # loop time the current body's headers were in
        _body_bytes = 0  # [B] received (framing included) since then

        # ------------------------------------------------------------------ headers
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

        # ------------------------------------------------------------------ body
        def _watch_body(self, was_in_body: bool, size: int) -> None:
            """After `size` bytes were read: (re)arm the body timer while a body is arriving."""
            if self.conn.their_state is not h11.SEND_BODY:
                self._cancel_body_timer()
                self._body_started_s = None
                return
            if self._body_started_s is None or not was_in_body:  # a new request's body
                self._body_started_s, self._body_bytes = self.loop.time(), 0
            else:
                self._body_bytes += size
            self._cancel_body_timer()
            deadline = self._body_started_s + body_pace.deadline_s(self._body_bytes)
            self._body_timer = self.loop.call_at(deadline, self._body_too_slow)

        def _cancel_body_timer(self) -> None:
            if self._body_timer is not None:
                self._body_timer.cancel()
                self._body_timer = None

        def _body_too_slow(self) -> None:
            self._body_timer = None
            if self.conn.their_state is not h11.SEND_BODY or self.transport.is_closing():
                return
            cycle = self.cycle
            if cycle is not None and not cycle.response_complete:
                # The app sees the client gone: its receive() says so, its answer is dropped.
                cycle.disconnected = True
                cycle.message_event.set()
            if self.conn.our_state is h11.SEND_RESPONSE:  # nothing answered yet
                self._send_408()
            self.transport.close()

        def _send_408(self) -> None:
            body = json.dumps({"detail": body_pace.too_slow_detail()}).encode()
            headers = [
                (b"content-type", b"application/json"),
                (b"content-length", str(len(body)).encode()),
                (b"connection", b"close"),
                *SECURITY_HEADERS.items(),
            ]
            for event in (
                h11.Response(status_code=408, headers=headers, reason=b"Request Timeout"),
                h11.Data(data=body),
                h11.EndOfMessage(),
            ):
                self.transport.write(self.conn.send(event))

        # ------------------------------------------------------------------ uvicorn's hooks
        def connection_made(self, transport: Any) -> None:  # type: ignore[override]
            super().connection_made(transport)
            self._arm_header_timer()

        def data_received(self, data: bytes) -> None:
            was_in_body = self.conn.their_state is h11.SEND_BODY
            super().data_received(data)
            if not self.transport.is_closing():
                self._watch_body(was_in_body, len(data))

        def on_response_complete(self) -> None:
            super().on_response_complete()
            if not self.transport.is_closing():
                self._arm_header_timer()

        def connection_lost(self, exc: Exception | None) -> None:
            self._cancel_header_timer()
            self._cancel_body_timer()
            super().connection_lost(exc)

    return TimedH11Protocol
