"""The hardware hub knows no run service: when a run's turn on a robot is over it tells the
listeners it was given a typed Stop, and one listener that fails does not silence the others."""

from __future__ import annotations

import time
from types import SimpleNamespace

from server.runs.commands import Stop
from server.service.hardware import SLOT_OVER, HardwareHub
from tests.waiting import wait_until

SLOT_S = 0.2  # [s] a short turn on the robot, so the hub's once-a-second tick ends it


def test_a_run_past_its_slot_is_told_to_stop_through_the_listeners():
    settings = SimpleNamespace(rosserial_port=-1, hardware_slot_s=SLOT_S,
                               hardware_start_within_s=60.0)  # fmt: skip
    hub = HardwareHub(store=None, settings=settings)  # no rosserial: nothing asks the store
    told: list[tuple[str, object]] = []

    def broken(run_id: str, command: object) -> None:
        raise RuntimeError("a listener that fails")

    hub.listen(broken)
    hub.listen(lambda run_id, command: told.append((run_id, command)))
    queue = hub.queue("crowbot-1")
    queue.join("ada", time.monotonic())
    queue.start("ada", "run-1", time.monotonic())
    hub.start()
    try:
        wait_until(lambda: told, 5.0, "the hub told its listener the slot is over")
    finally:
        hub.stop()
    assert told[0] == ("run-1", Stop(SLOT_OVER))
    assert "rosserial is switched off" in hub.listen_error
