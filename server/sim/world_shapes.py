"""Shapes a world file describes compactly, expanded to geometry: the four edges of a box, a row
of plants with gaps and a fixed jitter, a tape line through points with rounded corners."""

from __future__ import annotations

import itertools
import math

import numpy as np

DEFAULT_TAPE_MAX_SEGMENT_M = 0.05  # [m] line sensors sit ~1 cm apart; 5 cm chords keep curves true


class Problem(Exception):
    """Raised inside the parser with the text after "world '<id>': "."""


def box_edges(x: float, y: float, width: float, depth: float, yaw: float) -> list[tuple]:
    """The four edges (x1, y1, x2, y2) of a box centred at (x, y), `width` along its own x."""
    c, s = math.cos(yaw), math.sin(yaw)
    local = [
        (-width / 2, -depth / 2),
        (width / 2, -depth / 2),
        (width / 2, depth / 2),
        (-width / 2, depth / 2),
    ]
    corners = [(x + c * u - s * v, y + s * u + c * v) for u, v in local]
    return [(*corners[i], *corners[(i + 1) % 4]) for i in range(4)]


def plant_row(row: dict, where: str) -> list[tuple[float, float, float, float, str]]:
    (x0, y0), (x1, y1) = row["start"], row["end"]
    length = math.hypot(x1 - x0, y1 - y0)
    if length == 0.0:
        raise Problem(f"{where}: start and end are the same point; give the row a length")
    count = math.floor(length / row["spacing"] + 1e-9) + 1
    for i, gap in enumerate(row["gaps"]):
        if gap >= count:
            raise Problem(
                f"{where}.gaps[{i}] = {gap} is past the row's last plant (index "
                f"{count - 1}; the row has {count} plants)"
            )
    if row["jitter"] >= row["spacing"] / 2:
        raise Problem(
            f"{where}.jitter must be < spacing / 2 = {row['spacing'] / 2:g} (got {row['jitter']})"
        )
    ux, uy = (x1 - x0) / length, (y1 - y0) / length
    # A fixed seed from the file: the same world on every load, plants still not on a ruler line.
    offsets = np.random.default_rng(row["seed"]).uniform(-1.0, 1.0, size=(count, 2))
    offsets *= row["jitter"]
    plants = []
    for i in range(count):
        if i in row["gaps"]:
            continue
        along, across = i * row["spacing"] + offsets[i, 0], offsets[i, 1]
        px, py = x0 + ux * along - uy * across, y0 + uy * along + ux * across
        plants.append((px, py, row["radius"], row["height"], "plant"))
    return plants


def _split(p: np.ndarray, q: np.ndarray, max_len: float) -> list[np.ndarray]:
    pieces = max(1, math.ceil(np.linalg.norm(q - p) / max_len - 1e-9))
    return [p + (q - p) * k / pieces for k in range(1, pieces + 1)]


def tape_path(tape: dict, where: str) -> list[tuple[float, ...]]:
    """The tape's centre line as segments: corners rounded with `corner_radius` arcs, every
    straight and arc cut into pieces no longer than `max_segment`."""
    pts = [np.array(p, dtype=float) for p in tape["points"]]
    closed, radius, max_len = tape["closed"], tape["corner_radius"], tape["max_segment"]
    if closed and len(pts) < 3:
        raise Problem(f"{where}: a closed tape needs at least 3 points (got {len(pts)})")
    n = len(pts)
    for i in range(n if closed else n - 1):
        if np.allclose(pts[i], pts[(i + 1) % n]):
            raise Problem(f"{where}.points[{(i + 1) % n}] repeats the point before it; remove it")
    # Each corner becomes (entry point, arc points); open ends stay sharp.
    corners: list[tuple[np.ndarray, list[np.ndarray]]] = []
    for i in range(n):
        if radius == 0.0 or (not closed and i in (0, n - 1)):
            corners.append((pts[i], []))
            continue
        prev, here, nxt = pts[i - 1], pts[i], pts[(i + 1) % n]
        u1, u2 = (prev - here) / np.linalg.norm(prev - here), (nxt - here)
        u2 = u2 / np.linalg.norm(u2)
        turn = math.acos(float(np.clip(u1 @ u2, -1.0, 1.0)))  # angle between the two legs
        if turn > math.pi - 1e-9:
            corners.append((here, []))  # straight through: nothing to round
            continue
        tangent = radius / math.tan(turn / 2)
        legs = (np.linalg.norm(prev - here), np.linalg.norm(nxt - here))
        if tangent > min(legs) / 2 + 1e-9:
            raise Problem(
                f"{where}.corner_radius {radius:g} is too large for the corner at "
                f"points[{i}] (at most {radius * min(legs) / 2 / tangent:.3f} m)"
            )
        bisector = (u1 + u2) / np.linalg.norm(u1 + u2)
        centre = here + bisector * radius / math.sin(turn / 2)
        a0 = math.atan2(*(here + u1 * tangent - centre)[::-1])
        a1 = math.atan2(*(here + u2 * tangent - centre)[::-1])
        sweep = (a1 - a0 + math.pi) % (2 * math.pi) - math.pi  # the short way round
        steps = max(1, math.ceil(abs(sweep) * radius / max_len - 1e-9))
        arc = [
            centre
            + radius
            * np.array([math.cos(a0 + sweep * k / steps), math.sin(a0 + sweep * k / steps)])
            for k in range(steps + 1)
        ]
        corners.append((arc[0], arc[1:]))
    path: list[np.ndarray] = [corners[0][0], *corners[0][1]]
    order = list(range(1, n)) + ([0] if closed else [])
    for i in order:
        path += _split(path[-1], corners[i][0], max_len)
        if not (closed and i == 0):
            path += corners[i][1]
    return [(*a, *b, tape["width"], tape["darkness"]) for a, b in itertools.pairwise(path)]
