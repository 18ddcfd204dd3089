"""What every run measures: per node the loop period (p50, p95, p99, max, histogram, as the
response-time figures of 000_32b6074bbd2115c3.txt section 3.5 at 10 and 20 Hz), the wall time
each step computed, and the command latency (from the newest sensor message a node had seen to
its command taking effect on the robot); per run the collisions, distance travelled and time out
of bounds. Exercises add their own metrics from the recording.
"""

from __future__ import annotations

import numpy as np

HISTOGRAM_BINS = 20


class Samples:
    """A growing list of durations [s] with the summary the papers' figures show."""

    def __init__(self) -> None:
        self.values: list[float] = []

    def add(self, value_s: float) -> None:
        self.values.append(value_s)

    def summary(self) -> dict:
        if not self.values:
            return {"count": 0}
        data = np.asarray(self.values)
        p50, p95, p99 = np.percentile(data, [50, 95, 99])
        top = max(float(data.max()), 1e-9)
        counts, edges = np.histogram(data, bins=HISTOGRAM_BINS, range=(0.0, top))
        return {
            "count": len(self.values),
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
