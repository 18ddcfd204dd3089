"""No secret in any log line: the query values uvicorn logs with every path are redacted.

Invite links carry their token in the query (`/login?token=...`, a websocket's `?token=...`),
and uvicorn's access and error loggers (the latter logs websocket paths) write every path with
its raw query. Matching the raw text (`token=`) was not enough: the server reads the query
*decoded* (Starlette's `parse_qsl`), so `/login?tok%65n=<token>` logged in and logged the token.
So each query is split into its parameters and each name decoded, as the server reads it, before
it is judged:

- on `/login` no value is ever logged, whatever its name (a token pasted under another name,
  or without one, is still a token);
- elsewhere the value of every parameter whose decoded name contains a secret word
  (`SECRET_NAME_PARTS`) is replaced by `***`.

A redacted parameter is written with its decoded name when that is a plain word (the log then
says what the server understood: `token=***`), else as `***`: a decoded name is never written
raw, as `%0a` in it would forge a log line.
"""

from __future__ import annotations

import logging
import re
from urllib.parse import unquote_plus

REDACTED_LOGGERS = ("uvicorn.access", "uvicorn.error")
MASK = "***"
# Parameter names (decoded, lower case) whose value is a credential: a part of the name, so
# `access_token` and `session_token` are covered too.
SECRET_NAME_PARTS = ("token", "password", "secret")
# Paths every query value of which is redacted: the invite link's page (its last segment).
LOGIN_SEGMENT = "login"
# A path with its query inside a log message: uvicorn writes `quote(path)?raw_query`. The query
# runs to the next white space (a request target has none): a raw `"` or `'` in it must not end
# the match early and leave the rest of the query unread.
_PATH_AND_QUERY = re.compile(r"(?P<path>/[^\s?]*)\?(?P<query>\S*)")
# What is left of a `token=` outside any path's query (a message that quotes one bare).
_BARE_TOKEN = re.compile(r"(?i)(\btoken=)[^&;\s\"']+")
_PLAIN_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.-]{0,31}")
# Percent-decoding is repeated (a name encoded twice is decoded twice) up to this many times:
# more than any client needs, and a bound on the work a crafted name can cause.
MAX_DECODINGS = 4


def _decoded(text: str) -> str:
    for _ in range(MAX_DECODINGS):
        decoded = unquote_plus(text)
        if decoded == text:
            break
        text = decoded
    return text


def _is_login(path: str) -> bool:
    segments = [s for s in _decoded(path).split("/") if s]
    return bool(segments) and segments[-1].lower() == LOGIN_SEGMENT


def _is_secret(name: str) -> bool:
    lowered = name.lower()
    return any(part in lowered for part in SECRET_NAME_PARTS)


def _redacted_query(query: str, every_value: bool) -> str:
    # `&` is the server's separator; `;` too, so `a=1;token=x` is not logged whole as a's value.
    pieces = re.split(r"([&;])", query)
    out = []
    for piece in pieces:
        if piece in ("&", ";") or piece == "":
            out.append(piece)
            continue
        raw_name, has_value, _ = piece.partition("=")
        name = _decoded(raw_name)
        if not has_value:
            out.append(MASK if every_value else piece)  # a bare word on /login may be a token
        elif every_value or _is_secret(name):
            shown = name if _PLAIN_NAME.fullmatch(name) else MASK
            out.append(f"{shown}={MASK}")
        else:
            out.append(piece)
    return "".join(out)


def redact(text: str) -> str:
    """`text` with the query values that may be secrets replaced by `***` (module docstring)."""

    def one(found: re.Match[str]) -> str:
        path = found.group("path")
        return f"{path}?{_redacted_query(found.group('query'), _is_login(path))}"

    return _BARE_TOKEN.sub(rf"\1{MASK}", _PATH_AND_QUERY.sub(one, text))


class RedactTokens(logging.Filter):
    """Redacts a record's message and its string arguments (uvicorn passes the path as one)."""

    def filter(self, record: logging.LogRecord) -> bool:
        if isinstance(record.msg, str):
            record.msg = redact(record.msg)
        if isinstance(record.args, tuple):
            record.args = tuple(redact(a) if isinstance(a, str) else a for a in record.args)
        elif isinstance(record.args, dict):
            record.args = {
                key: redact(value) if isinstance(value, str) else value
                for key, value in record.args.items()
            }
        return True


def install_redaction() -> None:
    """After uvicorn configured its logging (uvicorn.Config does, on creation)."""
    for name in REDACTED_LOGGERS:
        logger = logging.getLogger(name)
        if not any(isinstance(f, RedactTokens) for f in logger.filters):
            logger.addFilter(RedactTokens())
