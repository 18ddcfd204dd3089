"""Geometry of small worlds in plain Python: ray casts of a few rays (the ultrasonic cone, the IR
beam) and the disc contact queries a physics tick makes while the robot touches something.

Every numpy call costs about a microsecond before it does any work, so the batched cast in
`obstacles.py` spends ~100-250 us on a 7-ray cast against a handful of walls, most of it in
call overhead; the same 28 ray-segment tests written as a Python loop take ~20 us. The CrowBot's
ultrasonic ranger samples 20 times a second in every run, so this matters when twenty realtime
runs share one interpreter. The arithmetic and the tie-breaking are those of
`Obstacles._cast_dense` (first minimum over segments, then circles, a circle only wins when
strictly closer), and the tests compare the two. The same holds for contacts: a robot resting
against a wall needs a contact query every physics tick, ~185 us each through numpy (5k steps/s)
against ~10 us here.
"""

from __future__ import annotations

import math
from typing import NamedTuple

PARALLEL_EPS = 1e-12  # [m^2] as in obstacles.py: |cross(d, e)| below this is parallel


class Segment(NamedTuple):
    start_x: float
    start_y: float
    edge_x: float
    edge_y: float
    normal_x: float
    normal_y: float
    height: float


class Circle(NamedTuple):
    x: float
    y: float
    radius_sq: float
    height: float


def cast_few(
    segments: list[Segment],
    circles: list[Circle],
    origin_x: float,
    origin_y: float,
    angles: list[float],
    max_range_m: float,
    min_height_m: float,
) -> tuple[list[float], list[float]]:
    """Per ray: the distance to the first surface (inf beyond `max_range_m`) and the cosine of
    the incidence angle (nan where nothing is hit)."""
    distances: list[float] = []
    cosines: list[float] = []
    for angle in angles:
        dx, dy = math.cos(angle), math.sin(angle)
        best, best_cos = math.inf, math.nan
        for seg in segments:
            if seg.height < min_height_m:
                continue
            denom = dx * seg.edge_y - dy * seg.edge_x
            if abs(denom) < PARALLEL_EPS:
                continue
            wx, wy = seg.start_x - origin_x, seg.start_y - origin_y
            t = (wx * seg.edge_y - wy * seg.edge_x) / denom
            s = (wx * dy - wy * dx) / denom
            if t >= 0.0 and 0.0 <= s <= 1.0 and t < best:
                best, best_cos = t, abs(seg.normal_x * dx + seg.normal_y * dy)
        circle_best, circle_cos = math.inf, math.nan
        for circle in circles:
            if circle.height < min_height_m:
                continue
            fx, fy = origin_x - circle.x, origin_y - circle.y
            b = fx * dx + fy * dy
            c = fx * fx + fy * fy - circle.radius_sq
            disc = b * b - c
            if disc < 0.0:
                continue
            t = 0.0 if c < 0.0 else -b - math.sqrt(disc)
            if t < 0.0 or t >= circle_best:
                continue
            hit_x, hit_y = origin_x + dx * t - circle.x, origin_y + dy * t - circle.y
            norm = max(math.hypot(hit_x, hit_y), 1e-12)
            circle_best, circle_cos = t, abs(hit_x / norm * dx + hit_y / norm * dy)
        if circle_best < best:
            best, best_cos = circle_best, circle_cos
        if best > max_range_m:
            best, best_cos = math.inf, math.nan
        distances.append(best)
        cosines.append(best_cos)
    return distances, cosines


def _closest_on_segment(seg: Segment, x: float, y: float) -> tuple[float, float]:
    """Vector from the closest point of `seg` to (x, y)."""
    rel_x, rel_y = x - seg.start_x, y - seg.start_y
    length_sq = max(seg.edge_x * seg.edge_x + seg.edge_y * seg.edge_y, 1e-18)
    along = min(1.0, max(0.0, (rel_x * seg.edge_x + rel_y * seg.edge_y) / length_sq))
    return rel_x - along * seg.edge_x, rel_y - along * seg.edge_y


def contacts_few(
    segments: list[Segment], circles: list[Circle], x: float, y: float, radius_m: float
) -> tuple[list[tuple[float, float]], float]:
    """Push-out vectors for every surface a disc of `radius_m` at (x, y) overlaps (segments
    first, then circles, as `Obstacles.contacts` orders them), and the distance [m] from (x, y)
    to the nearest surface (as `clearance_few`), in one pass."""
    pushes = []
    nearest = math.inf
    for seg in segments:
        away_x, away_y = _closest_on_segment(seg, x, y)
        gap = math.hypot(away_x, away_y)
        nearest = min(nearest, gap)
        if gap < radius_m:
            gap = max(gap, 1e-9)
            pushes.append((away_x / gap * (radius_m - gap), away_y / gap * (radius_m - gap)))
    for circle in circles:
        away_x, away_y = x - circle.x, y - circle.y
        gap = math.hypot(away_x, away_y)
        circle_radius = math.sqrt(circle.radius_sq)
        nearest = min(nearest, gap - circle_radius)
        overlap = radius_m + circle_radius - gap
        if overlap > 0.0:
            gap = max(gap, 1e-9)
            pushes.append((away_x / gap * overlap, away_y / gap * overlap))
    return pushes, nearest


def clearance_few(segments: list[Segment], circles: list[Circle], x: float, y: float) -> float:
    """Distance [m] from (x, y) to the nearest surface (inf in an empty world)."""
    nearest = math.inf
    for seg in segments:
        nearest = min(nearest, math.hypot(*_closest_on_segment(seg, x, y)))
    for circle in circles:
        nearest = min(nearest, math.hypot(x - circle.x, y - circle.y) - math.sqrt(circle.radius_sq))
    return nearest
