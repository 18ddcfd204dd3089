"""The editor's analysers on generated stubs, shared by a test session: writing the stubs takes
about a second and jedi's first look at rospy and numpy several more. `editor` is the service
with its sandboxed host (server/editor/sandbox_host.py), started once for the session."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from pathlib import Path

import pytest

from server.editor.complete import Analyser
from server.editor.context import RunContext
from server.editor.limits import LIMITS
from server.editor.service import EditorService
from server.editor.stubs import write_stubs
from server.sim import robot_ids
from tests.waiting import wait_until

START_S = 180.0  # [s] the host's start and warm-up on a loaded 2-core machine
MAX_CODE_BYTES = 256 * 1024  # [bytes] the lab's default per-file limit


@pytest.fixture(scope="session")
def stub_root(tmp_path_factory) -> Path:
    return write_stubs(tmp_path_factory.mktemp("editor-stubs"))


@pytest.fixture(scope="session")
def analyser(stub_root) -> Analyser:
    return Analyser(stub_root, robot_ids())


@pytest.fixture(scope="session")
def jedi_cache(tmp_path_factory) -> Path:
    """jedi's parse cache, shared by every host the session starts: the second starts warm."""
    return tmp_path_factory.mktemp("jedi-cache")


def started_service(jedi_cache: Path, **limits) -> EditorService:
    """An EditorService whose host answers, with `limits` changed from the lab's table."""
    service = EditorService(MAX_CODE_BYTES, cache_dir=jedi_cache)
    if limits:
        service.limits = dataclasses.replace(LIMITS, **limits)
        service.host.limits = service.gate.limits = service.limits
    service.start()
    wait_until(service.host.ready.is_set, START_S, "the editor's analysis host is ready")
    # Its first requests meet a host still warming up on matplotlib and scipy.
    wait_until(lambda: service.complete("import rospy\nrospy.", 2, 6, RunContext(None))[
        "completions"], START_S, "the editor's analysis answers a completion")  # fmt: skip
    return service


@pytest.fixture(scope="session")
def editor(jedi_cache) -> Iterator[EditorService]:
    service = started_service(jedi_cache)
    yield service
    service.close()


def cursor_at_end(code: str) -> tuple[int, int]:
    """(line, column) just after the last character of `code` (1-based line, 0-based column)."""
    lines = code.split("\n")
    return len(lines), len(lines[-1])
