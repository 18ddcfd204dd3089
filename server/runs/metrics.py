"""What every run measures: per node the loop period (p50, p95, p99, max, histogram, as the
response-time figures of 000_32b6074bbd2115c3.txt section 3.5 at 10 and 20 Hz), the wall time
each step computed, the command latency (from the newest sensor message a node had seen to its
command taking effect on the robot) and the wake lateness (how much later than the time it asked
for a node was woken: zero in lockstep, the machine's share of a realtime run's timing, with the
latest wakes and when they came); per run the collisions, distance travelled and time out of
bounds. Exercises add their own metrics from the recording.
"""

from __future__ import annotations

import heapq
from array import array

import numpy as np

HISTOGRAM_BINS = 20
RECENT_SAMPLES = 1000  # a live summary looks at this many newest values: cheap to ask often
# [wakes] a node's latest wakes kept with their run time, so that what a late wake did (an
# open-loop move that went on longer) can be told from the recording; any other wake was at most
# as late as the least late of these. A loaded machine's spikes are a few a run; keeping 50
# brings the bound on the rest down to about the 90th percentile of a 10 s realtime run's
# lateness, for ~2.5 KB of metrics a node.
LATEST_WAKES_KEPT = 50


class Samples:
    """A growing list of durations [s] with the summary the papers' figures show. Kept as a
    C array of doubles (8 bytes a value, not a Python float's 32): a ten-minute run at 100 Hz
    holds 60,000 values per node and measure."""

    def __init__(self) -> None:
        self.values: array = array("d")

    def add(self, value_s: float) -> None:
        self.values.append(value_s)

    def recent_summary(self) -> dict:
        """The summary of the newest RECENT_SAMPLES values: for live views polled often."""
        return _summary(self.values[-RECENT_SAMPLES:])

    def summary(self) -> dict:
        return _summary(self.values[:])


def _summary(values: array) -> dict:
    """`values` is a copy: a numpy view of the live array would stop the run thread from
    appending (an array exporting its buffer cannot grow).

    The figures are numpy's (`percentile`'s linear method, `histogram`'s bins), computed from
    one sort: np.percentile and np.histogram took ~360 us on 1,000 values, and a worker reads
    a summary of every live run once a second (issue 16)."""
    data = np.frombuffer(values, dtype=np.float64)
    if not len(data):
        return {"count": 0}
    ordered = np.sort(data)
    p50, p95, p99 = (_percentile(ordered, q) for q in (0.50, 0.95, 0.99))
    top = max(float(ordered[-1]), 1e-9)
    edges = np.linspace(0.0, top, HISTOGRAM_BINS + 1)
    # Bin i holds edges[i] <= x < edges[i + 1], the last one its right edge too (np.histogram).
    bounds = np.searchsorted(ordered, edges, side="left")
    bounds[-1] = np.searchsorted(ordered, edges[-1], side="right")
    return {
        "count": len(data),
        "mean_s": float(data.mean()),  # over the values in their order, as numpy sums them
        "p50_s": p50,
        "p95_s": p95,
        "p99_s": p99,
        "max_s": float(ordered[-1]),
        "histogram": {"edges_s": edges.tolist(), "counts": np.diff(bounds).tolist()},
    }


def _percentile(ordered: np.ndarray, quantile: float) -> float:
    """np.percentile(..., method="linear") of sorted values, to the last bit: the same
    interpolation, written as numpy's _lerp writes it (from the nearer neighbour)."""
    index = quantile * (len(ordered) - 1)
    below = int(index)
    above = min(below + 1, len(ordered) - 1)
    fraction = index - below
    low, high = float(ordered[below]), float(ordered[above])
    step = high - low
    if fraction >= 0.5:
        return high - step * (1.0 - fraction)
    return low + step * fraction


class NodeMetrics:
    def __init__(self) -> None:
        self.period = Samples()  # run time between successive wakes
        self.compute = Samples()  # wall time from wake to its reply
        self.latency = Samples()  # newest sensor message seen -> command applied
        # Run time from the wake time a node asked for to its wake (`woke_late`).
        self.lateness = Samples()
        self._latest: list[tuple[float, float]] = []  # min-heap of (lateness [s], run time [s])
        self.wakes = 0
        self.published = 0
        self.rejected_commands = 0

    def woke_late(self, at_s: float, lateness_s: float) -> None:
        """A wake at run time `at_s` [s] that came because the node's wake time did (not a
        message first), `lateness_s` [s] after it. Lockstep wakes on time; a realtime wake is
        late when the machine is busy, and the node acts that much later than it meant to."""
        self.lateness.add(lateness_s)
        if lateness_s <= 0.0:
            return  # on time: nothing to tell (a wake not listed was no later than the listed)
        if len(self._latest) < LATEST_WAKES_KEPT:
            heapq.heappush(self._latest, (lateness_s, at_s))
        elif lateness_s > self._latest[0][0]:
            heapq.heapreplace(self._latest, (lateness_s, at_s))

    def latest_wakes(self) -> list[dict]:
        """The latest wakes (at most LATEST_WAKES_KEPT, each later than 0), in run-time order.
        Fewer than that: no other wake was late; as many: no other was later than the least."""
        return [
            {"at_s": at_s, "late_s": lateness_s}
            for lateness_s, at_s in sorted(self._latest, key=lambda wake: wake[1])
        ]

    def summary(self) -> dict:
        return {
            "wakes": self.wakes,
            "published": self.published,
            "rejected_commands": self.rejected_commands,
            "period": self.period.summary(),
            "compute": self.compute.summary(),
            "command_latency": self.latency.summary(),
            "wake_lateness": self.lateness.summary(),
            "latest_wakes": self.latest_wakes(),
        }
