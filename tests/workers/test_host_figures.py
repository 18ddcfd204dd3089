"""A worker's published status reuses its measured figures between recomputations (issue 16:
computing them for every status was a third of a worker's CPU at 100 runs)."""

from __future__ import annotations

import math
from types import SimpleNamespace

from server.runs.metrics import NodeMetrics
from server.workers import host
from server.workers.host import RunHost, _Hosted


class _Bus:
    def __init__(self) -> None:
        self.messages = 0

    def graph(self) -> dict:
        return {"nodes": ["robot"], "topics": [{"name": "Distance", "messages": self.messages,
                                                "rate_hz": math.nan}]}  # fmt: skip


def _hosted_run(periods_s: list[float]) -> tuple[_Hosted, dict]:
    metrics = NodeMetrics()
    for period in periods_s:
        metrics.period.add(period)
    slots = {"controller": SimpleNamespace(metrics=metrics)}
    hosted = _Hosted(job=None, outbox=None, run=SimpleNamespace(bus=_Bus()))
    return hosted, slots


def test_figures_are_reused_until_due_then_recomputed(monkeypatch) -> None:
    clock = [100.0]
    monkeypatch.setattr(host.time, "monotonic", lambda: clock[0])
    hosted, slots = _hosted_run([0.1, 0.1, 0.1])
    periods, graph = RunHost._figures(hosted, slots)
    assert periods["controller"]["count"] == 3
    assert graph["topics"][0]["rate_hz"] is None  # JSON-safe: no NaN on the wire

    slots["controller"].metrics.period.add(0.3)
    hosted.run.bus.messages = 7
    clock[0] += host.FIGURES_EVERY_S / 2
    assert RunHost._figures(hosted, slots) == (periods, graph)  # not yet: the same figures

    clock[0] += host.FIGURES_EVERY_S / 2
    periods, graph = RunHost._figures(hosted, slots)
    assert periods["controller"]["count"] == 4
    assert periods["controller"]["max_s"] == 0.3
    assert graph["topics"][0]["messages"] == 7


def test_a_node_that_comes_is_in_the_next_status_at_once(monkeypatch) -> None:
    monkeypatch.setattr(host.time, "monotonic", lambda: 50.0)
    hosted, slots = _hosted_run([0.05])
    RunHost._figures(hosted, slots)
    slots["follower"] = SimpleNamespace(metrics=NodeMetrics())
    periods, _ = RunHost._figures(hosted, slots)
    assert set(periods) == {"controller", "follower"}
