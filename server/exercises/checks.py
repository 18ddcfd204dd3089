"""Metrics the checks are made of, each a function of a run's evidence. Units in the names."""

from __future__ import annotations

import math

import numpy as np

from server.exercises.evidence import Evidence


def readings(evidence: Evidence, topic: str, scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(times [s], values) of a std_msgs scalar topic, `data` times `scale`."""
    series = evidence.series(topic)
    times = np.array([t for t, _ in series])
    values = np.array([float(message.data) * scale for _, message in series])
    return times, values


def settling_time_s(times: np.ndarray, values: np.ndarray, target: float, band: float) -> float:
    """First time after which `values` stay within `band` of `target` (inf if never)."""
    outside = np.abs(values - target) > band
    if not len(values) or outside[-1]:
        return math.inf
    last_outside = np.flatnonzero(outside)
    return float(times[last_outside[-1] + 1]) if len(last_outside) else float(times[0])


def mean_abs_error(values: np.ndarray, target: float) -> float:
    return float(np.mean(np.abs(values - target))) if len(values) else math.inf


def collisions(evidence: Evidence) -> float:
    return float(evidence.result.metrics["collisions"])
