"""Who is asking: a session cookie (browsers) or `Authorization: Bearer <token>` (API clients,
the invite token). FastAPI dependencies give routes the user, or answer 401 with what to do.

Cookie: HttpOnly (scripts cannot read it), SameSite=Strict (no other site can make the browser
send it, which is our CSRF defence), Secure when the request came over TLS.
"""

from __future__ import annotations

from dataclasses import dataclass

from fastapi import Depends, HTTPException, Request, WebSocket, status

from server.store import accounts
from server.store.accounts import Role
from server.store.db import Store

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
