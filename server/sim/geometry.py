"""Plane geometry shared by the world, its solid surfaces and the floor sensors: distances from a
point to line segments (walls, box edges, tape strips) and to circles (plants, posts); and a
heading as the quaternion ROS messages carry (`yaw_quaternion`, the one place it is written).

Segments are (N, 4) rows (x1, y1, x2, y2) [m]; the queries take them as `segment_arrays` returns
them, so a caller that asks many times (`Obstacles`) prepares the arrays once.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

_MIN_LENGTH_SQ = 1e-18  # [m^2] a zero-length segment is its start point, not a division by zero


class Quaternion(NamedTuple):
    """A unit quaternion's components in ROS order (geometry_msgs/Quaternion: x, y, z, w)."""

    x: float
    y: float
    z: float
    w: float


def yaw_quaternion(yaw_rad: float) -> Quaternion:
    """The rotation by `yaw_rad` [rad] about +z (counter-clockwise seen from above, REP 103).

    A plain tuple so ROS 1 and ROS 2 messages alike take it: `Quaternion(*q)`, `**q._asdict()`."""
    half = 0.5 * float(yaw_rad)
    return Quaternion(0.0, 0.0, math.sin(half), math.cos(half))


def segment_arrays(segments: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(starts (N, 2), vectors (N, 2) from start to end, squared lengths (N,)) of the rows."""
    rows = np.asarray(segments, dtype=np.float64).reshape(-1, 4)
    starts = rows[:, 0:2]
    vectors = rows[:, 2:4] - starts
    length_sq = np.maximum(np.hypot(vectors[:, 0], vectors[:, 1]) ** 2, _MIN_LENGTH_SQ)
    return starts, vectors, length_sq


def offsets_from_segments(
    point: np.ndarray, starts: np.ndarray, vectors: np.ndarray, length_sq: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """For each segment, the vector (N, 2) from its point closest to `point` (2,) to `point`, and
    its length (N,) [m]: the distance from the point to the segment."""
    along = np.clip(np.sum((point - starts) * vectors, axis=1) / length_sq, 0.0, 1.0)
    offsets = point - (starts + along[:, None] * vectors)
    return offsets, np.hypot(offsets[:, 0], offsets[:, 1])


def distance_to_nearest(
    point: np.ndarray,
    segments: tuple[np.ndarray, np.ndarray, np.ndarray],
    centres: np.ndarray,
    radii: np.ndarray,
) -> float:
    """Distance [m] from `point` (2,) to the nearest segment or circle surface (negative inside a
    circle; inf when there is nothing). `segments` is what `segment_arrays` returns."""
    nearest = math.inf
    if len(segments[0]):
        nearest = float(np.min(offsets_from_segments(point, *segments)[1]))
    if len(centres):
        away = point - centres
        nearest = min(nearest, float(np.min(np.hypot(away[:, 0], away[:, 1]) - radii)))
    return nearest
