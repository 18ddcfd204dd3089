"""The editor's analysers on generated stubs, shared by a test session: writing the stubs takes
about a second and jedi's first look at rospy and numpy several more."""

from __future__ import annotations

from pathlib import Path

import pytest

from server.editor.complete import Analyser
from server.editor.stubs import write_stubs
from server.sim import robot_ids


@pytest.fixture(scope="session")
def stub_root(tmp_path_factory) -> Path:
    return write_stubs(tmp_path_factory.mktemp("editor-stubs"))


@pytest.fixture(scope="session")
def analyser(stub_root) -> Analyser:
    return Analyser(stub_root, robot_ids())


def cursor_at_end(code: str) -> tuple[int, int]:
    """(line, column) just after the last character of `code` (1-based line, 0-based column)."""
    lines = code.split("\n")
    return len(lines), len(lines[-1])
