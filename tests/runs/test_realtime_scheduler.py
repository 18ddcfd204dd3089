"""The realtime scheduler steps the runs that are due together earliest deadline first."""

from __future__ import annotations

import os
import threading
import time

from server.runs.clocks import RealtimeScheduler


class _Driver:
    """Stands in for a RealtimeDriver: one step, recorded, then done."""

    def __init__(self, name: str, deadline: float, order: list[str]) -> None:
        self.name = name
        self.deadline = deadline
        self.fds: list[int] = []
        self.finished = threading.Event()
        self.error: BaseException | None = None
        self._order = order

    def step(self) -> bool:
        self._order.append(self.name)
        return False


def test_runs_due_together_are_stepped_earliest_deadline_first() -> None:
    scheduler = RealtimeScheduler()
    order: list[str] = []
    now = time.monotonic()
    # Listed latest first: stepping in list order would give c, b, a.
    drivers = [
        _Driver("c", now - 0.001, order),
        _Driver("b", now - 0.002, order),
        _Driver("a", now - 0.003, order),
    ]
    with scheduler._lock:  # all three in before the loop looks
        scheduler._drivers.extend(drivers)
    os.write(scheduler._wakeup_w, b"!")
    for driver in drivers:
        assert driver.finished.wait(5.0)
    assert order == ["a", "b", "c"]
