"""A node's wake lateness: every wake in its summary, the latest ones with their run time, and
what is left out no later than what is kept."""

from __future__ import annotations

import random

from server.runs.metrics import LATEST_WAKES_KEPT, NodeMetrics


def test_the_latest_wakes_are_kept_with_their_time_and_bound_the_others() -> None:
    metrics = NodeMetrics()
    rng = random.Random(3)
    wakes = [(index * 0.01, rng.expovariate(200.0)) for index in range(1000)]  # [s], [s]
    for at_s, lateness_s in wakes:
        metrics.woke_late(at_s, lateness_s)
    latest = metrics.latest_wakes()
    assert len(latest) == LATEST_WAKES_KEPT
    assert [wake["at_s"] for wake in latest] == sorted(wake["at_s"] for wake in latest)
    kept = {(wake["at_s"], wake["late_s"]) for wake in latest}
    assert kept == set(sorted(wakes, key=lambda wake: wake[1])[-LATEST_WAKES_KEPT:])
    left_out = [lateness_s for at_s, lateness_s in wakes if (at_s, lateness_s) not in kept]
    assert max(left_out) <= min(wake["late_s"] for wake in latest)
    summary = metrics.summary()
    assert summary["wake_lateness"]["count"] == 1000
    assert summary["wake_lateness"]["max_s"] == max(lateness_s for _, lateness_s in wakes)
    assert summary["latest_wakes"] == latest


def test_wakes_on_time_are_counted_and_not_listed() -> None:
    metrics = NodeMetrics()
    for index in range(3 * LATEST_WAKES_KEPT):
        metrics.woke_late(index * 0.05, 0.0)
    metrics.woke_late(7.5, 0.004)
    assert metrics.latest_wakes() == [{"at_s": 7.5, "late_s": 0.004}]
    assert metrics.summary()["wake_lateness"]["count"] == 3 * LATEST_WAKES_KEPT + 1
