"""A real launcher (bubblewrap sandbox, warm pool) shared by the run tests of a module."""

from __future__ import annotations

import dataclasses

import pytest

from sandbox import bwrap
from sandbox.launcher import Launcher
from sandbox.limits import DEFAULT_LIMITS


@pytest.fixture(scope="module")
def launcher():
    problem = bwrap.probe()
    if problem:
        pytest.fail(f"the run tests need bubblewrap: {problem} (./scripts/test installs it)")
    limits = dataclasses.replace(DEFAULT_LIMITS, step_budget_s=2.0, first_step_budget_s=8.0)
    launcher = Launcher(limits=limits, pool_size=2)
    yield launcher
    launcher.close()
