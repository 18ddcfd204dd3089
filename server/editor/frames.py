"""The wire between the server and the editor's analysis host (server/editor/host.py), and
between the host and each request's process: msgspec Structs in length-prefixed msgpack frames
(sandbox/protocol.py's FrameReader and FrameWriter), one message per event.

    host -> server:  Ready                       warm, taking jobs
    server -> host:  Job                         any number at once (the server's gate bounds
    host -> server:  Answer | Refused            them), each answered once, by its id

    request -> host: Parsed ...                  library modules jedi parsed for the first time
    request -> host: Done                        and then its answer; it exits
"""

from __future__ import annotations

from enum import StrEnum
from typing import Any

import msgspec


class Op(StrEnum):
    CHECKS = "checks"  # our API checks and Python's own syntax verdict (api_checks, syntax)
    COMPLETE = "complete"  # jedi's completions and signature help
    HOVER = "hover"  # jedi's text for the name at the cursor
    RUFF_CHECK = "ruff_check"  # ruff's pyflakes findings and syntax errors
    RUFF_FORMAT = "ruff_format"  # ruff format


RUFF_OPS = frozenset({Op.RUFF_CHECK, Op.RUFF_FORMAT})


class Cause(StrEnum):
    """Why a job got no answer."""

    TIME = "time"  # past its time budget: killed by the host
    CPU = "cpu"  # past its CPU seconds: killed by the kernel (RLIMIT_CPU)
    MEMORY = "memory"  # past its memory cap (MemoryError, or ruff could not allocate)
    BUSY = "busy"  # the host already runs as many requests as it may
    FAILED = "failed"  # anything else: a crash, an error of the analysers, an unreadable answer


class Ready(msgspec.Struct, tag=True, frozen=True):
    """The host has loaded jedi and warmed it up; it takes jobs now."""

    startup_s: float  # [s] from the host's first instruction to this frame


class Job(msgspec.Struct, tag=True, frozen=True):
    """Analyse `code` (`op`) for `user` (whose analysis process may answer their next jobs
    too, never another's); line and column for completion and hover (1-based line, 0-based
    column); the robot and the topics its exercise's built-in nodes publish."""

    id: int
    op: Op
    code: str
    user: str = ""
    line: int = 1
    column: int = 0
    robot: str | None = None
    extra_topics: list[tuple[str, str]] = []


class Answer(msgspec.Struct, tag=True, frozen=True):
    """A job's result, as the analysers give it: for ruff's ops {"returncode", "stdout",
    "stderr", "truncated"}, for the others the route's JSON."""

    id: int
    result: dict[str, Any]


class Refused(msgspec.Struct, tag=True, frozen=True):
    """A job without an answer; `reason` is a sentence for the student (without its full
    stop), `cause` what stopped it."""

    id: int
    cause: Cause
    reason: str


class Parsed(msgspec.Struct, tag=True, frozen=True):
    """A request's jedi parsed a library module that was in no cache (parso's grammar hash and
    the file); the host parses it too, for the requests that come after."""

    grammar: str
    path: str


class Done(msgspec.Struct, tag=True, frozen=True):
    """A request's end: its result, or a sentence saying why there is none."""

    result: dict[str, Any] | None = None
    error: str | None = None
    cause: Cause = Cause.FAILED


ToHost = Job
ToServer = Ready | Answer | Refused
FromRequest = Parsed | Done
