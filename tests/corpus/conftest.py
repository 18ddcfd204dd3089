"""A real launcher (bubblewrap sandbox, warm pool, the default limits students get) shared by
the corpus runs."""

from __future__ import annotations

import pytest

from sandbox import bwrap
from sandbox.launcher import Launcher


@pytest.fixture(scope="module")
def launcher():
    problem = bwrap.probe()
    if problem:
        pytest.fail(f"the corpus tests need bubblewrap: {problem} (./scripts/test installs it)")
    launcher = Launcher(pool_size=2)
    yield launcher
    launcher.close()
