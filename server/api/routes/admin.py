"""Instructor admin API, users: create one or many (from CSV), list, disable/enable, new token.
Students get 404 for every admin route, as if it did not exist."""

from __future__ import annotations

import csv
import io

from fastapi import APIRouter, Depends, HTTPException, Request

from server.api.auth import Caller, instructor
from server.api.routes.runs import iso
from server.api.schemas import UserCreate, UserUpdate
from server.store import accounts
from server.store.accounts import Role
from server.store.models import User

router = APIRouter(prefix="/api/admin", tags=["admin"])
MAX_BULK_USERS = 500  # rows per CSV import: a large course, not a denial of service
CSV_EXAMPLE = "name,email\nAda Lovelace,ada@example.org"


def user_out(user: User, request: Request, token: str | None = None) -> dict:
    out = {
        "id": user.id,
        "name": user.name,
        "email": user.email,
        "role": user.role,
        "disabled": user.disabled,
        "created_at": iso(user.created_at),
        "token_created_at": iso(user.token_created_at),
    }
    if token is not None:  # the only time the plain token is shown
        out["token"] = token
        out["invite_url"] = f"{request.app.state.settings.base_url()}/login?token={token}"
    return out


def _user(request: Request, user_id: str, db) -> User:
    user = accounts.get_user(db, user_id)
    if user is None:
        raise HTTPException(404, f"no user '{user_id}'")
    return user


def _enrol(db, course_id: str | None, user: User) -> None:
    if course_id is None:
        return
    from server.store import courses

    if courses.get(db, course_id) is None:
        raise HTTPException(
            404, f"no course '{course_id}'; create it first (POST /api/admin/courses)"
        )
    courses.enrol(db, course_id, user.id)


@router.post("/users", status_code=201, summary="Create a user; answers with an invite link")
def create_user(body: UserCreate, request: Request, _: Caller = Depends(instructor)) -> dict:
    with request.app.state.store.session() as db:
        made = accounts.create_user(db, body.name, Role(body.role), body.email)
        _enrol(db, body.course, made.user)
        return user_out(made.user, request, made.token)


@router.post(
    "/users/bulk",
    status_code=201,
    summary="Create students from CSV (header: name,email; email optional)",
    openapi_extra={"requestBody": {"content": {"text/csv": {"example": CSV_EXAMPLE}}}},
)
async def bulk_create(request: Request, course: str | None = None, _: Caller = Depends(instructor)):
    raw = await request.body()
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise HTTPException(422, "the CSV is not UTF-8 text") from None
    rows = list(csv.DictReader(io.StringIO(text)))
    if not rows or "name" not in (rows[0].keys() if rows else ()):
        raise HTTPException(
            422, f"the CSV needs a header line with a 'name' column, e.g.\n{CSV_EXAMPLE}"
        )
    if len(rows) > MAX_BULK_USERS:
        raise HTTPException(422, f"at most {MAX_BULK_USERS} users per import, got {len(rows)}")
    checked = []
    for number, row in enumerate(rows, start=2):  # line 1 is the header
        try:
            checked.append(UserCreate(name=(row.get("name") or "").strip(),
                                      email=(row.get("email") or "").strip() or None,
                                      course=course))  # fmt: skip
        except ValueError as error:
            first = (
                error.errors()[0] if hasattr(error, "errors") else {"loc": (), "msg": str(error)}
            )
            field = ".".join(str(p) for p in first["loc"])
            raise HTTPException(422, f"CSV line {number}: {field}: {first['msg']}") from None
    from starlette.concurrency import run_in_threadpool

    def create_all() -> list[dict]:
        with request.app.state.store.session() as db:
            out = []
            for item in checked:
                made = accounts.create_user(db, item.name, Role.STUDENT, item.email)
                _enrol(db, course, made.user)
                out.append(user_out(made.user, request, made.token))
            return out

    return {"users": await run_in_threadpool(create_all)}


@router.get("/users", summary="Every user")
def list_users(request: Request, role: Role | None = None, _: Caller = Depends(instructor)):
    with request.app.state.store.session() as db:
        return {"users": [user_out(u, request) for u in accounts.list_users(db, role)]}


@router.get("/users/{user_id}", summary="One user")
def get_user(user_id: str, request: Request, _: Caller = Depends(instructor)) -> dict:
    with request.app.state.store.session() as db:
        return user_out(_user(request, user_id, db), request)


@router.patch("/users/{user_id}", summary="Rename, disable or enable a user")
def update_user(
    user_id: str, body: UserUpdate, request: Request, caller: Caller = Depends(instructor)
) -> dict:
    with request.app.state.store.session() as db:
        user = _user(request, user_id, db)
        if body.name is not None:
            user.name = body.name
        if body.disabled is not None:
            if body.disabled and user.id == caller.id:
                raise HTTPException(422, "you cannot disable yourself; ask another instructor")
            accounts.set_disabled(db, user, body.disabled)
        out = user_out(user, request)
    if body.disabled:
        request.app.state.sockets.revoke(user_id)  # live views and 3D views close now
        out["runs_stopped"] = request.app.state.runs.stop_user(user_id, "the user was disabled")
    return out


@router.post("/users/{user_id}/disable", summary="Disable a user: sessions end, runs stop")
def disable_user(user_id: str, request: Request, caller: Caller = Depends(instructor)) -> dict:
    return update_user(user_id, UserUpdate(disabled=True), request, caller)


@router.post("/users/{user_id}/token", summary="A new invite token (the old one stops working)")
def renew_token(user_id: str, request: Request, _: Caller = Depends(instructor)) -> dict:
    with request.app.state.store.session() as db:
        made = accounts.renew_token(db, _user(request, user_id, db))
        return user_out(made.user, request, made.token)
