"""Waiting for a condition in a test, with a deadline, instead of sleeping a fixed time.

A fixed sleep is both too long (every run pays it) and too short (a loaded machine misses it);
a poll ends as soon as the condition holds and fails, with a sentence, when it never does."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")

POLL_S = 0.01  # [s] between two looks: short beside any deadline, long beside a look's cost


class ConditionTimeout(AssertionError):
    """A condition a test waited for did not come true in time."""


def wait_until(
    predicate: Callable[[], T], timeout_s: float, what: str, poll_s: float = POLL_S
) -> T:
    """Call `predicate` until it returns something true, and return that; raise
    ConditionTimeout naming `what` (the condition, e.g. "the run paused") after `timeout_s`
    [s] of wall time. A look that ends past the deadline still counts."""
    deadline = time.monotonic() + timeout_s
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() >= deadline:
            raise ConditionTimeout(
                f"waited {timeout_s:g} s for this, and it did not happen: {what}"
            )
        time.sleep(poll_s)
