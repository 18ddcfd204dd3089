"""What every run measures: per node the loop period (p50, p95, p99, max, histogram, as the
response-time figures of 000_32b6074bbd2115c3.txt section 3.5 at 10 and 20 Hz), the wall time
each step computed, and the command latency (from the newest sensor message a node had seen to
its command taking effect on the robot); per run the collisions, distance travelled and time out
of bounds. Exercises add their own metrics from the recording.
"""

from __future__ import annotations

from array import array

import numpy as np

HISTOGRAM_BINS = 20
RECENT_SAMPLES = 1000  # a live summary looks at this many newest values: cheap to ask often


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
    appending (an array exporting its buffer cannot grow)."""
    data = np.frombuffer(values, dtype=np.float64)
    if not len(data):
        return {"count": 0}
    p50, p95, p99 = np.percentile(data, [50, 95, 99])
    top = max(float(data.max()), 1e-9)
    counts, edges = np.histogram(data, bins=HISTOGRAM_BINS, range=(0.0, top))
    return {
        "count": len(data),
        "mean_s": float(data.mean()),
        "p50_s": float(p50),
        "p95_s": float(p95),
        "p99_s": float(p99),
        "max_s": float(data.max()),
        "histogram": {"edges_s": edges.tolist(), "counts": counts.tolist()},
    }


class NodeMetrics:
    def __init__(self) -> None:
        self.period = Samples()  # run time between successive wakes
        self.compute = Samples()  # wall time from wake to its reply
        self.latency = Samples()  # newest sensor message seen -> command applied
        self.wakes = 0
        self.published = 0
        self.rejected_commands = 0

    def summary(self) -> dict:
        return {
            "wakes": self.wakes,
            "published": self.published,
            "rejected_commands": self.rejected_commands,
            "period": self.period.summary(),
            "compute": self.compute.summary(),
            "command_latency": self.latency.summary(),
        }
