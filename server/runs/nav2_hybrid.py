"""A Hybrid-A* planner for the nav2 built-in, as the thesis uses Nav2's SMAC Hybrid-A* planner
with its Stanley controller (003_4f92d1fa0a49ddae.txt section 5.9): paths a car with a minimum
turning radius could drive, so the robot approaches the goal on an arc and arrives with the
goal's heading instead of turning on the spot at the end.

The search is Dolgov et al.'s Hybrid A* ("Path Planning for Autonomous Vehicles in Unknown
Semi-structured Environments", IJRR 2010): continuous (x, y, heading) states expanded by three
forward motion primitives (left arc, straight, right arc of the minimum turning radius), a
closed set over (cell, heading bin), the cost-to-go of a 2D Dijkstra over the grown grid (the
"holonomic with obstacles" heuristic), and every few expansions an analytic expansion: a Dubins
path to the goal (Dubins 1957; the six words LSL, RSR, LSR, RSL, RLR, LRL), taken when it is
free. SMAC's defaults where they apply: 72 heading bins, forward only ("DUBIN" motion model).
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable

import numpy as np

HEADING_BINS = 72  # SMAC's angle_quantization_bins
MIN_TURNING_RADIUS_M = 0.4  # [m] SMAC's minimum_turning_radius default
STEP_M = 0.1  # [m] length of one motion primitive (two map cells)
SAMPLE_M = 0.025  # [m] spacing of the collision checks along a primitive or a Dubins path
ANALYTIC_EVERY = 5  # expansions between two tries of a Dubins path to the goal
MAX_EXPANSIONS = 60_000  # give up (no path) after this many expansions
TURN_PENALTY = 1.05  # cost factor of an arc over a straight step (SMAC's non-straight penalty)

Pose = tuple[float, float, float]


def _mod2pi(angle: float) -> float:
    return angle % (2.0 * math.pi)


def dubins_words(q0: Pose, q1: Pose, radius: float) -> list[tuple[str, tuple[float, ...]]]:
    """Every feasible Dubins word from q0 to q1: (word, segment lengths in radians of turn or,
    for S, in units of `radius`), shortest first."""
    dx, dy = q1[0] - q0[0], q1[1] - q0[1]
    d = math.hypot(dx, dy) / radius
    theta = _mod2pi(math.atan2(dy, dx))
    a, b = _mod2pi(q0[2] - theta), _mod2pi(q1[2] - theta)
    sa, sb, ca, cb = math.sin(a), math.sin(b), math.cos(a), math.cos(b)
    cab = math.cos(a - b)
    words = []
    p2 = 2 + d * d - 2 * cab + 2 * d * (sa - sb)  # LSL
    if p2 >= 0:
        tmp = math.atan2(cb - ca, d + sa - sb)
        words.append(("LSL", (_mod2pi(tmp - a), math.sqrt(p2), _mod2pi(b - tmp))))
    p2 = 2 + d * d - 2 * cab + 2 * d * (sb - sa)  # RSR
    if p2 >= 0:
        tmp = math.atan2(ca - cb, d - sa + sb)
        words.append(("RSR", (_mod2pi(a - tmp), math.sqrt(p2), _mod2pi(tmp - b))))
    p2 = -2 + d * d + 2 * cab + 2 * d * (sa + sb)  # LSR
    if p2 >= 0:
        p = math.sqrt(p2)
        tmp = math.atan2(-ca - cb, d + sa + sb) - math.atan2(-2.0, p)
        words.append(("LSR", (_mod2pi(tmp - a), p, _mod2pi(tmp - b))))
    p2 = d * d - 2 + 2 * cab - 2 * d * (sa + sb)  # RSL
    if p2 >= 0:
        p = math.sqrt(p2)
        tmp = math.atan2(ca + cb, d - sa - sb) - math.atan2(2.0, p)
        words.append(("RSL", (_mod2pi(a - tmp), p, _mod2pi(b - tmp))))
    tmp = (6.0 - d * d + 2 * cab + 2 * d * (sa - sb)) / 8.0  # RLR
    if abs(tmp) <= 1:
        p = _mod2pi(2 * math.pi - math.acos(tmp))
        t = _mod2pi(a - math.atan2(ca - cb, d - sa + sb) + p / 2)
        words.append(("RLR", (t, p, _mod2pi(a - b - t + p))))
    tmp = (6.0 - d * d + 2 * cab + 2 * d * (sb - sa)) / 8.0  # LRL
    if abs(tmp) <= 1:
        p = _mod2pi(2 * math.pi - math.acos(tmp))
        t = _mod2pi(-a - math.atan2(ca - cb, d + sa - sb) + p / 2)
        words.append(("LRL", (t, p, _mod2pi(b - a - t + p))))
    return sorted(words, key=lambda word: sum(word[1]))


def drive(start: Pose, moves: list[tuple[str, float]], radius: float, spacing: float) -> list:
    """Poses every `spacing` metres along segments ("L"/"R": radians of turn, "S": metres)."""
    x, y, yaw = start
    poses = []
    for kind, amount in moves:
        length = amount * radius if kind in "LR" else amount
        steps = max(1, math.ceil(length / spacing))
        for _ in range(steps):
            ds = length / steps
            if kind == "S":
                x, y = x + ds * math.cos(yaw), y + ds * math.sin(yaw)
            else:
                turn = ds / radius * (1.0 if kind == "L" else -1.0)
                # exact arc: chord along the mean heading
                chord = 2.0 * radius * math.sin(abs(turn) / 2.0)
                x += chord * math.cos(yaw + turn / 2.0)
                y += chord * math.sin(yaw + turn / 2.0)
                yaw += turn
            poses.append((x, y, yaw))
    return poses


def dubins_path(q0: Pose, q1: Pose, radius: float, free: Callable[[float, float], bool]) -> list:
    """The shortest collision-free Dubins path's poses from q0 to q1, or []."""
    for word, lengths in dubins_words(q0, q1, radius):
        moves = [
            (kind, length * (radius if kind == "S" else 1.0))
            for kind, length in zip(word, lengths, strict=True)
        ]
        poses = drive(q0, moves, radius, SAMPLE_M)
        if all(free(x, y) for x, y, _ in poses):
            return poses
    return []


def hybrid_astar(
    start: Pose,
    goal: Pose,
    free: Callable[[float, float], bool],
    distance_to_goal: Callable[[float, float], float],
    cell_m: float,
    radius: float = MIN_TURNING_RADIUS_M,
) -> list[Pose]:
    """Poses from `start` to exactly `goal` (heading included) for a forward-only car of
    minimum turning radius `radius`; [] if none was found. `free(x, y)`: the robot fits there;
    `distance_to_goal(x, y)`: the obstacle-aware 2D distance (the heuristic)."""
    turn = STEP_M / radius
    primitives = ((turn, TURN_PENALTY), (0.0, 1.0), (-turn, TURN_PENALTY))
    bin_rad = 2.0 * math.pi / HEADING_BINS

    def key(pose: Pose) -> tuple[int, int, int]:
        return (
            math.floor(pose[0] / cell_m),
            math.floor(pose[1] / cell_m),
            round(_mod2pi(pose[2]) / bin_rad) % HEADING_BINS,
        )

    parents: dict[tuple[int, int, int], tuple[Pose, tuple | None, list]] = {}
    best = {key(start): 0.0}
    parents[key(start)] = (start, None, [start])
    frontier = [(distance_to_goal(start[0], start[1]), 0.0, key(start), start)]
    expansions = 0
    while frontier and expansions < MAX_EXPANSIONS:
        _, cost, node, pose = heapq.heappop(frontier)
        if cost > best.get(node, math.inf):
            continue
        expansions += 1
        if expansions % ANALYTIC_EVERY == 1 or distance_to_goal(pose[0], pose[1]) < 2 * radius:
            shot = dubins_path(pose, goal, radius, free)
            if shot:
                return _chain(parents, node) + shot
        for dyaw, penalty in primitives:
            moves = [("S", STEP_M)] if dyaw == 0.0 else [("L" if dyaw > 0 else "R", abs(dyaw))]
            segment = drive(pose, moves, radius, SAMPLE_M)
            if not all(free(x, y) for x, y, _ in segment):
                continue
            end = segment[-1]
            nxt = key(end)
            new_cost = cost + STEP_M * penalty
            if new_cost < best.get(nxt, math.inf):
                best[nxt] = new_cost
                parents[nxt] = (end, node, segment)
                estimate = new_cost + distance_to_goal(end[0], end[1])
                heapq.heappush(frontier, (estimate, new_cost, nxt, end))
    return []


def _chain(parents: dict, node: tuple) -> list[Pose]:
    segments = []
    while node is not None:
        _, parent, segment = parents[node]
        segments.append(segment)
        node = parent
    return [pose for segment in reversed(segments) for pose in segment]


def grid_distance(blocked: np.ndarray, goal: tuple[int, int], cell_m: float) -> np.ndarray:
    """Dijkstra distance [m] of every free cell to `goal` over 8-connected free cells (inf where
    the goal cannot be reached): Hybrid A*'s obstacle-aware heuristic."""
    height, width = blocked.shape
    distance = np.full(blocked.shape, np.inf)
    distance[goal] = 0.0
    frontier = [(0.0, goal)]
    steps = [(dr, dc, math.hypot(dr, dc) * cell_m) for dr in (-1, 0, 1) for dc in (-1, 0, 1)]
    while frontier:
        d, (row, col) = heapq.heappop(frontier)
        if d > distance[row, col]:
            continue
        for dr, dc, length in steps:
            r, c = row + dr, col + dc
            inside = (dr or dc) and 0 <= r < height and 0 <= c < width
            if inside and not blocked[r, c] and d + length < distance[r, c]:
                distance[r, c] = d + length
                heapq.heappush(frontier, (d + length, (r, c)))
    return distance
