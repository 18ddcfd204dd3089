"""Users, their tokens and browser sessions.

A user has one token: the invite link's, which also works as `Authorization: Bearer` until it is
renewed or the user is disabled. Opening the invite link makes a session (a second, random
token in an HttpOnly cookie). Only sha256 hashes of tokens are stored: tokens are 32 random
bytes, so a fast hash is enough (nothing to brute-force), and a leaked table logs nobody in.
"""

from __future__ import annotations

import hashlib
import secrets
import time
import uuid
from dataclasses import dataclass
from enum import StrEnum

from sqlalchemy import delete, select
from sqlalchemy.orm import Session as Db

from server.store.models import Session, User

TOKEN_BYTES = 32  # [bytes] of randomness per token
SESSION_LIFETIME_S = 14 * 24 * 3600.0  # [s] a browser stays logged in for two weeks


class Role(StrEnum):
    STUDENT = "student"
    INSTRUCTOR = "instructor"


def new_token() -> str:
    return secrets.token_urlsafe(TOKEN_BYTES)


def hash_token(token: str) -> str:
    return hashlib.sha256(token.encode()).hexdigest()


@dataclass(frozen=True, slots=True)
class NewUser:
    """A user just made or given a new token: the only moment the plain token exists."""

    user: User
    token: str


def create_user(db: Db, name: str, role: Role, email: str | None = None) -> NewUser:
    now = time.time()
    token = new_token()
    user = User(
        id=uuid.uuid4().hex,
        name=name,
        email=email,
        role=str(role),
        disabled=False,
        token_hash=hash_token(token),
        token_created_at=now,
        created_at=now,
    )
    db.add(user)
    db.flush()
    return NewUser(user, token)


def renew_token(db: Db, user: User) -> NewUser:
    """A new token; the old one (and every session made with it) stops working."""
    token = new_token()
    user.token_hash = hash_token(token)
    user.token_created_at = time.time()
    end_sessions(db, user.id)
    db.flush()
    return NewUser(user, token)


def user_by_token(db: Db, token: str) -> User | None:
    user = db.scalar(select(User).where(User.token_hash == hash_token(token)))
    return user if user is not None and not user.disabled else None


def get_user(db: Db, user_id: str) -> User | None:
    return db.get(User, user_id)


def list_users(db: Db, role: Role | None = None) -> list[User]:
    query = select(User).order_by(User.created_at, User.name)
    if role is not None:
        query = query.where(User.role == str(role))
    return list(db.scalars(query))


def instructors_exist(db: Db) -> bool:
    return db.scalar(select(User.id).where(User.role == str(Role.INSTRUCTOR)).limit(1)) is not None


def set_disabled(db: Db, user: User, disabled: bool) -> None:
    user.disabled = disabled
    if disabled:
        end_sessions(db, user.id)
    db.flush()


def create_session(db: Db, user: User) -> str:
    token = new_token()
    now = time.time()
    db.add(
        Session(
            token_hash=hash_token(token),
            user_id=user.id,
            created_at=now,
            expires_at=now + SESSION_LIFETIME_S,
        )
    )
    db.flush()
    return token


def user_by_session(db: Db, token: str) -> User | None:
    session = db.get(Session, hash_token(token))
    if session is None or session.expires_at < time.time():
        return None
    user = db.get(User, session.user_id)
    return user if user is not None and not user.disabled else None


def end_session(db: Db, token: str) -> None:
    db.execute(delete(Session).where(Session.token_hash == hash_token(token)))


def end_sessions(db: Db, user_id: str) -> None:
    db.execute(delete(Session).where(Session.user_id == user_id))
