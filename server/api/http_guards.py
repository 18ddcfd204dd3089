"""Guards every HTTP request passes before any route or login check sees it, as pure ASGI
middleware (no request object built, nothing buffered):

- `BodyLimit` counts the bytes of a request body as they arrive, chunked or not, and answers
  413 as soon as they pass the limit (a Content-Length over it is refused before a byte is read).
  Starlette's `Request.body()` assembles the whole body in memory; counting has to happen in
  `receive` (ASGI spec, "HTTP Connection Scope": http.request messages with more_body).
- `BodyPace` is how long a request body may take, once its headers are in: whole within a
  timeout, and at a minimum average rate after a grace (Apache mod_reqtimeout's `body=..,MinRate`
  idea). uvicorn has no timer while a body arrives, so 50 connections sending a login body 1 byte
  every 4 s stayed open past 72 s; its h11 protocol (server/api/http_server.py) enforces this,
  answering 408 with `too_slow_detail`.
- `SecurityHeaders` adds a Content-Security-Policy, frame-ancestors / X-Frame-Options, nosniff
  and a Referrer-Policy to every response that does not set its own (the proxied 3D view does).
  The policy allows what web/index.html, web/admin.html and their bundles load: scripts and
  styles from /static only, inline styles (CodeMirror adds <style> elements where a browser
  lacks adoptable style sheets), data:/blob: images and downloads, the 3D view's frame from this
  site, and fetch/websocket to this site only (CSP Level 3: 'self' covers ws: and wss:).
"""

from __future__ import annotations

import json
from collections.abc import Awaitable, Callable, MutableMapping
from dataclasses import dataclass
from typing import Any

Scope = MutableMapping[str, Any]
Message = MutableMapping[str, Any]
Receive = Callable[[], Awaitable[Message]]
Send = Callable[[Message], Awaitable[None]]
ASGIApp = Callable[[Scope, Receive, Send], Awaitable[None]]

CONTENT_SECURITY_POLICY = "; ".join(
    [
        "default-src 'self'",
        "script-src 'self'",
        "style-src 'self' 'unsafe-inline'",
        "img-src 'self' data: blob:",
        "font-src 'self' data:",
        "connect-src 'self'",
        "frame-src 'self'",
        "worker-src 'self' blob:",
        "object-src 'none'",
        "base-uri 'self'",
        "form-action 'self'",
        "frame-ancestors 'self'",  # the 3D view is framed by the student page, nothing else is
    ]
)
SECURITY_HEADERS: dict[bytes, bytes] = {
    b"content-security-policy": CONTENT_SECURITY_POLICY.encode(),
    b"x-frame-options": b"SAMEORIGIN",  # browsers without frame-ancestors
    b"x-content-type-options": b"nosniff",  # an artifact named .txt is never run as a script
    b"referrer-policy": b"same-origin",  # no run id or page address leaks to another site
}


def too_large_detail(max_bytes: int) -> str:
    return (
        f"the request body is larger than {max_bytes} bytes, the lab's limit for any request; "
        "send less (a workspace file over the limit belongs in several smaller files)"
    )


@dataclass(frozen=True, slots=True)
class BodyPace:
    """How long a request body may take after its headers (settings.py says why each value)."""

    timeout_s: float  # [s] the whole body, however fast it comes
    min_rate_bytes_s: float  # [B/s] on average, counted once the grace is over
    grace_s: float  # [s] before the rate counts

    def deadline_s(self, received_bytes: int) -> float:
        """[s] after the headers, when a body with `received_bytes` in is too slow: each
        `min_rate_bytes_s` received buys a second past the grace, up to the timeout."""
        return min(self.timeout_s, self.grace_s + received_bytes / self.min_rate_bytes_s)

    def too_slow_detail(self) -> str:
        return (
            f"the request body arrived too slowly: a body must be complete within "
            f"{self.timeout_s:g} s of its headers, and after its first {self.grace_s:g} s "
            f"arrive at {self.min_rate_bytes_s:g} bytes a second or faster; send it again "
            "from a faster connection"
        )


class BodyLimit:
    """Refuses a request body over `max_bytes` with 413 while it is still arriving."""

    def __init__(self, app: ASGIApp, max_bytes: int) -> None:
        self.app = app
        self.max_bytes = max_bytes

    async def _refuse(self, send: Send) -> None:
        body = json.dumps({"detail": too_large_detail(self.max_bytes)}).encode()
        await send(
            {
                "type": "http.response.start",
                "status": 413,
                "headers": [
                    (b"content-type", b"application/json"),
                    (b"content-length", str(len(body)).encode()),
                    (b"connection", b"close"),  # the rest of the body is never read
                ],
            }
        )
        await send({"type": "http.response.body", "body": body})

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        for name, value in scope["headers"]:
            if name == b"content-length" and (not value.isdigit() or int(value) > self.max_bytes):
                await self._refuse(send)
                return
        received = 0
        refused = False
        response_started = False

        async def counted_receive() -> Message:
            nonlocal received, refused
            if refused:
                return {"type": "http.disconnect"}
            message = await receive()
            if message["type"] == "http.request":
                received += len(message.get("body", b""))
                if received > self.max_bytes:
                    refused = True
                    if not response_started:
                        await self._refuse(send)
                    # The app sees the client gone: it stops reading and its answer is dropped.
                    return {"type": "http.disconnect"}
            return message

        async def guarded_send(message: Message) -> None:
            nonlocal response_started
            if refused:
                return
            if message["type"] == "http.response.start":
                response_started = True
            await send(message)

        await self.app(scope, counted_receive, guarded_send)


class SecurityHeaders:
    """Adds SECURITY_HEADERS to every HTTP response that has not set them itself."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return

        async def with_headers(message: Message) -> None:
            if message["type"] == "http.response.start":
                headers = list(message.get("headers", []))
                present = {name.lower() for name, _ in headers}
                headers += [(k, v) for k, v in SECURITY_HEADERS.items() if k not in present]
                message["headers"] = headers
            await send(message)

        await self.app(scope, receive, with_headers)
