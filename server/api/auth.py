"""Who is asking: a session cookie (browsers) or `Authorization: Bearer <token>` (API clients,
the invite token). FastAPI dependencies give routes the user, or answer 401 with what to do.

Cookie: HttpOnly (scripts cannot read it), SameSite=Strict (no other site can make the browser
send it), Secure when the request came over TLS.

CSRF: SameSite=Strict does not cover another port or a sibling subdomain of the same site (they
are "same-site"), so every state change that is not a Bearer request must also come from the
lab's own origin: `Sec-Fetch-Site` same-origin (or absent) and `Origin`, when sent, equal to the
scheme://host:port the request came to or to `public_url` (OWASP CSRF Prevention Cheat Sheet,
"Verifying Origin With Standard Headers" and "Fetch Metadata"). Browsers send Origin on every
POST, PUT, PATCH and DELETE and on every websocket handshake; scripts with a Bearer token are not
browsers and need neither (a cross-origin page cannot add an Authorization header without a
preflight we never grant). Websockets check the Origin the same way (`foreign_origin`).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from urllib.parse import urlsplit

from fastapi import Depends, HTTPException, Request, WebSocket, status
from starlette.datastructures import Headers
from starlette.responses import JSONResponse
from starlette.types import ASGIApp, Receive, Scope, Send

from server.store import accounts
from server.store.accounts import Role
from server.store.db import Store

log = logging.getLogger("robodojo.api")
SESSION_COOKIE = "robodojo_session"


@dataclass(frozen=True, slots=True)
class Caller:
    """The authenticated user, detached from any database session."""

    id: str
    name: str
    role: Role

    @property
    def is_instructor(self) -> bool:
        return self.role is Role.INSTRUCTOR

    @property
    def who(self) -> str:
        """How a stop by this caller is told in the run's reason ("stopped by the user")."""
        return "an instructor" if self.is_instructor else "the user"

    def can_see(self, owner_id: str) -> bool:
        """A student sees their own things; an instructor sees everyone's."""
        return owner_id == self.id or self.is_instructor


def bearer_token(header: str | None) -> str | None:
    if not header:
        return None
    scheme, _, token = header.partition(" ")
    return token.strip() if scheme.lower() == "bearer" and token.strip() else None


def resolve(store: Store, cookie: str | None, bearer: str | None) -> Caller | None:
    with store.session() as db:
        user = None
        if bearer:
            user = accounts.user_by_token(db, bearer)
        elif cookie:
            user = accounts.user_by_session(db, cookie)
        if user is None:
            return None
        return Caller(user.id, user.name, Role(user.role))


NOT_LOGGED_IN = (
    "not logged in: open your invite link (…/login?token=…) in this browser, or send "
    "'Authorization: Bearer <your token>'"
)


def current_user(request: Request) -> Caller:
    store: Store = request.app.state.store
    caller = resolve(
        store,
        request.cookies.get(SESSION_COOKIE),
        bearer_token(request.headers.get("authorization")),
    )
    if caller is None:
        raise HTTPException(
            status.HTTP_401_UNAUTHORIZED, NOT_LOGGED_IN, headers={"WWW-Authenticate": "Bearer"}
        )
    return caller


def instructor(caller: Caller = Depends(current_user)) -> Caller:
    if not caller.is_instructor:
        # 404, not 403: a student learns nothing about what exists behind the admin API.
        raise HTTPException(status.HTTP_404_NOT_FOUND, "Not Found")
    return caller


def websocket_user(websocket: WebSocket) -> Caller | None:
    store: Store = websocket.app.state.store
    header = websocket.headers.get("authorization")
    token = bearer_token(header) or websocket.query_params.get("token")
    return resolve(store, websocket.cookies.get(SESSION_COOKIE), token)


def secure_request(request: Request) -> bool:
    return request.url.scheme == "https"


SAFE_METHODS = frozenset({"GET", "HEAD", "OPTIONS"})  # read only: no CSRF check
DEFAULT_PORTS = {"http": 80, "https": 443}
WEB_SCHEMES = {"ws": "http", "wss": "https", "http": "http", "https": "https"}


def _origin_key(url: str) -> tuple[str, str, int] | None:
    """(scheme, host, port) of an origin or URL, default ports filled in; None if unreadable."""
    try:
        parts = urlsplit(url.strip())
        scheme = WEB_SCHEMES.get(parts.scheme.lower())
        if scheme is None or not parts.hostname:
            return None
        return scheme, parts.hostname.lower(), parts.port or DEFAULT_PORTS[scheme]
    except ValueError:  # a port that is not a number
        return None


def lab_origins(scope: Scope) -> set[tuple[str, str, int]]:
    """The origins the lab's own pages have: the one this request came to, and `public_url`."""
    headers = Headers(scope=scope)
    scheme = WEB_SCHEMES.get(scope.get("scheme", "http"), "http")
    origins = set()
    own = _origin_key(f"{scheme}://{headers.get('host', '')}")
    if own is not None:
        origins.add(own)
    settings = getattr(scope["app"].state, "settings", None)
    public_url = getattr(settings, "public_url", None)
    if public_url and (public := _origin_key(public_url)) is not None:
        origins.add(public)
    return origins


def foreign_origin(scope: Scope) -> str | None:
    """The Origin header when it names another origin than the lab's; None when it is ours or
    absent (not a browser)."""
    origin = Headers(scope=scope).get("origin")
    if origin is None:
        return None
    return None if _origin_key(origin) in lab_origins(scope) else origin


def csrf_refusal(scope: Scope) -> str | None:
    """Why a state-changing browser request is refused (a sentence), or None to let it through."""
    if scope["method"] in SAFE_METHODS:
        return None
    headers = Headers(scope=scope)
    if bearer_token(headers.get("authorization")):
        return None
    fetch_site = headers.get("sec-fetch-site")
    if fetch_site is not None and fetch_site.lower() != "same-origin":
        return (
            f"refused: this request came from another site's page (Sec-Fetch-Site: {fetch_site}); "
            "use the lab's own page, or send 'Authorization: Bearer <your token>' from a script"
        )
    origin = foreign_origin(scope)
    if origin is not None:
        return (
            f"refused: this request came from a page at {origin}, not from the lab's own origin; "
            "use the lab's own page, or send 'Authorization: Bearer <your token>' from a script"
        )
    return None


class CsrfGuard:
    """ASGI middleware: every HTTP request passes `csrf_refusal` before any route (403 if not)."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] == "http":
            refusal = csrf_refusal(scope)
            if refusal is not None:
                log.warning("%s %s: %s", scope["method"], scope.get("path", ""), refusal)
                await JSONResponse({"detail": refusal}, status_code=403)(scope, receive, send)
                return
        await self.app(scope, receive, send)
