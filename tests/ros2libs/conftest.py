"""A real launcher (bubblewrap sandbox, warm pool) for the tests that run ROS 2 nodes."""

from __future__ import annotations

import pytest

from sandbox import bwrap
from sandbox.launcher import Launcher


@pytest.fixture(scope="module")
def launcher():
    problem = bwrap.probe()
    if problem:
        pytest.fail(f"these tests run real nodes and need bubblewrap: {problem}")
    launcher = Launcher(pool_size=2)
    yield launcher
    launcher.close()
