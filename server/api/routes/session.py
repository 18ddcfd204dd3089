"""Logging in and out. `/login?token=…` is the invite link (and the link the server prints at
first start): it sets the session cookie and sends the browser to the lab's page.

Login CSRF (issue 14): a link may name any account, so a browser already signed in as someone
else is not switched by opening it: it gets a page asking first, whose button POSTs the token
back to `/login` from the lab's own page; only that POST switches. A browser with no session (or
signed in as the same user) is logged in at once, as before."""

from __future__ import annotations

import html
from urllib.parse import parse_qs

from fastapi import APIRouter, Depends, HTTPException, Request, Response
from fastapi.responses import HTMLResponse, RedirectResponse
from starlette.concurrency import run_in_threadpool

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


def _bad_link() -> HTMLResponse:
    return HTMLResponse(
        f"<!doctype html><title>RoboDojo</title><p>{html.escape(BAD_TOKEN)}</p>",
        status_code=401,
    )


def _signed_in(request: Request, session_token: str) -> Response:
    """303 to the page, so a reload does not resend the token; the token leaves the address bar.
    Instructors land on their console, students on the lab."""
    with request.app.state.store.session() as db:
        user = accounts.user_by_session(db, session_token)
        landing = "/admin" if user is not None and user.role == "instructor" else "/"
    response = RedirectResponse(landing, status_code=303)
    _set_cookie(response, request, session_token)
    response.headers["Referrer-Policy"] = "no-referrer"
    return response


def _switch_page(current: Caller, name: str, token: str) -> HTMLResponse:
    """Asks before signing a browser that is someone's into another account."""
    landing = "/admin" if current.is_instructor else "/"
    page = (
        "<!doctype html><html lang='en'><meta charset='utf-8'><title>RoboDojo: switch user?</title>"
        f"<p>You are signed in as <strong>{html.escape(current.name)}</strong>. "
        f"Sign in as <strong>{html.escape(name)}</strong> instead?</p>"
        "<form method='post' action='/login'>"
        f"<input type='hidden' name='token' value='{html.escape(token, quote=True)}'>"
        f"<button type='submit'>Sign in as {html.escape(name)}</button> "
        f"<a href='{landing}'>Stay signed in as {html.escape(current.name)}</a></form></html>"
    )
    # strict-origin, not no-referrer: under no-referrer Chromium sends the form's POST with
    # `Origin: null`, which the CSRF guard refuses; strict-origin still keeps the token (in this
    # page's address) out of every Referer.
    return HTMLResponse(
        page, headers={"Cache-Control": "no-store", "Referrer-Policy": "strict-origin"}
    )


@router.get("/login", include_in_schema=False)
def login_link(request: Request, token: str = "") -> Response:
    with request.app.state.store.session() as db:
        named = accounts.user_by_token(db, token) if token else None
        named_id, named_name = (named.id, named.name) if named is not None else (None, "")
    if named_id is None:
        return _bad_link()
    current = resolve(request.app.state.store, request.cookies.get(SESSION_COOKIE), None)
    if current is not None and current.id != named_id:
        return _switch_page(current, named_name, token)
    session_token = _login(request, token)
    return _bad_link() if session_token is None else _signed_in(request, session_token)


@router.post("/login", include_in_schema=False)
async def login_confirmed(request: Request) -> Response:
    """The switch page's button: its form body carries the token. The CSRF guard (auth.py) has
    already refused another origin; a request with neither Origin nor Sec-Fetch-Site did not come
    from a browser's page and is refused too (scripts use POST /api/session)."""
    if "origin" not in request.headers and "sec-fetch-site" not in request.headers:
        raise HTTPException(403, "sign in from the lab's own page, or POST /api/session")
    fields = parse_qs((await request.body()).decode("utf-8", "replace"))
    token = (fields.get("token") or [""])[0]
    session_token = await run_in_threadpool(_login, request, token) if token else None
    if session_token is None:
        return _bad_link()
    return await run_in_threadpool(_signed_in, request, session_token)


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
