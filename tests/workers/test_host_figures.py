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


def test_a_summary_is_numpys_percentiles_and_histogram_to_the_last_bit() -> None:
    """The summary sorts once instead of calling np.percentile and np.histogram; its figures
    must be theirs exactly (ties, one value, all zeros, values on bin edges included)."""
    import random
    from array import array

    import numpy as np

    from server.runs.metrics import HISTOGRAM_BINS, _summary

    rng = random.Random(4)
    cases = [[0.1], [0.0] * 7, [0.1] * 1000, [0.05, 0.1, 0.1, 0.15] * 25]
    cases += [[abs(rng.gauss(0.1, 0.02)) for _ in range(rng.randint(2, 1200))] for _ in range(60)]
    cases += [[rng.choice([0.0, 0.05, 0.1]) for _ in range(rng.randint(2, 300))] for _ in range(20)]
    for values in cases:
        data = np.array(values)
        summary = _summary(array("d", values))
        p50, p95, p99 = np.percentile(data, [50, 95, 99])
        counts, edges = np.histogram(data, bins=HISTOGRAM_BINS, range=(0.0, max(data.max(), 1e-9)))
        assert (summary["p50_s"], summary["p95_s"], summary["p99_s"]) == (p50, p95, p99)
        assert summary["histogram"] == {"edges_s": edges.tolist(), "counts": counts.tolist()}
        assert summary["max_s"] == data.max() and summary["mean_s"] == data.mean()
