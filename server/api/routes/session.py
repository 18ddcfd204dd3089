"""Logging in and out. `/login?token=…` is the invite link (and the link the server prints at
first start): it sets the session cookie and sends the browser to the lab's page."""

from __future__ import annotations

import html

from fastapi import APIRouter, Depends, HTTPException, Request, Response
from fastapi.responses import HTMLResponse, RedirectResponse

from server.api.auth import (
    SESSION_COOKIE,
    Caller,
    bearer_token,
    current_user,
    resolve,
    secure_request,
)
from server.api.schemas import SessionCreate
from server.store import accounts
from server.store.accounts import SESSION_LIFETIME_S

router = APIRouter(tags=["session"])

BAD_TOKEN = (
    "This login link is not valid: it was mistyped, renewed or its user disabled. Ask your "
    "instructor for a new invite link."
)


def _set_cookie(response: Response, request: Request, session_token: str) -> None:
    response.set_cookie(
        SESSION_COOKIE,
        session_token,
        max_age=int(SESSION_LIFETIME_S),
        httponly=True,
        samesite="strict",
        secure=secure_request(request),
        path="/",
    )


def _login(request: Request, token: str) -> str | None:
    with request.app.state.store.session() as db:
        user = accounts.user_by_token(db, token)
        if user is None:
            return None
        return accounts.create_session(db, user)


@router.get("/login", include_in_schema=False)
def login_link(request: Request, token: str = "") -> Response:
    session_token = _login(request, token) if token else None
    if session_token is None:
        return HTMLResponse(
            f"<!doctype html><title>RoboDojo</title><p>{html.escape(BAD_TOKEN)}</p>",
            status_code=401,
        )
    # 303 to the page, so a reload does not resend the token; the token leaves the address bar.
    # Instructors land on their console, students on the lab.
    with request.app.state.store.session() as db:
        user = accounts.user_by_session(db, session_token)
        landing = "/admin" if user is not None and user.role == "instructor" else "/"
    response = RedirectResponse(landing, status_code=303)
    _set_cookie(response, request, session_token)
    response.headers["Referrer-Policy"] = "no-referrer"
    return response


@router.post("/api/session", summary="Log in with a token; sets the session cookie")
def login(body: SessionCreate, request: Request, response: Response) -> dict:
    session_token = _login(request, body.token)
    if session_token is None:
        raise HTTPException(401, BAD_TOKEN)
    _set_cookie(response, request, session_token)
    return {"ok": True}


@router.post("/api/logout", summary="End this browser's session")
def logout(request: Request, response: Response) -> dict:
    token = request.cookies.get(SESSION_COOKIE)
    if token:
        with request.app.state.store.session() as db:
            accounts.end_session(db, token)
    response.delete_cookie(SESSION_COOKIE, path="/")
    return {"ok": True}


@router.get("/api/session", summary="Who is logged in, if anyone (never 401: for pages)")
def session_state(request: Request) -> dict:
    caller = resolve(
        request.app.state.store,
        request.cookies.get(SESSION_COOKIE),
        bearer_token(request.headers.get("authorization")),
    )
    if caller is None:
        return {"user": None}
    return {"user": {"id": caller.id, "name": caller.name, "role": str(caller.role)}}


@router.get("/api/me", summary="Who is logged in")
def me(caller: Caller = Depends(current_user)) -> dict:
    return {"id": caller.id, "name": caller.name, "role": str(caller.role)}
