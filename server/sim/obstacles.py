"""Solid world geometry prepared for fast queries: ray casts for the range sensors, and the
distance from a circular robot body to the nearest surfaces for collisions.

Everything is vectorized over rays x surfaces with numpy (no Python loop over beams), so a
360-degree scan of a few hundred beams against a crop field of plants costs one batch of array
operations. Surfaces are the world's wall/box segments and cylinders (plants, posts); each has a
height, so a sensor that looks at a horizontal slice above the floor (the TurtleBot's depth scan
at ~0.45 m, 003_4f92d1fa0a49ddae.txt section 5) can ignore what is lower than its slice.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from server.sim.world import World

_PARALLEL_EPS = 1e-12  # [m^2] |cross(d, e)| below this: ray parallel to the segment, no hit


@dataclass(frozen=True, slots=True)
class RayHits:
    """Result of a ray cast, one entry per ray.

    `distance_m` is the range to the first surface (inf where nothing is hit within range);
    `incidence_rad` is the angle between the ray and the surface normal at the hit (0 = the ray
    meets the surface head-on, pi/2 = grazing; nan where nothing is hit).
    """

    distance_m: np.ndarray
    incidence_rad: np.ndarray


class Obstacles:
    """The world's solid surfaces as flat arrays, built once per simulation."""

    def __init__(self, world: World) -> None:
        segments = np.asarray(world.segments, dtype=np.float64).reshape(-1, 4)
        circles = np.asarray(world.circles, dtype=np.float64).reshape(-1, 3)
        self.segment_start = segments[:, 0:2]
        self.segment_vector = segments[:, 2:4] - segments[:, 0:2]
        lengths = np.hypot(self.segment_vector[:, 0], self.segment_vector[:, 1])
        self.segment_length_sq = np.maximum(lengths**2, 1e-18)
        # Unit normals; the sign does not matter because incidence uses |cos|.
        self.segment_normal = (
            np.stack([-self.segment_vector[:, 1], self.segment_vector[:, 0]], axis=1)
            / np.maximum(lengths, 1e-9)[:, None]
        )
        self.segment_height = np.asarray(world.segment_height, dtype=np.float64).reshape(-1)
        self.circle_centre = circles[:, 0:2]
        self.circle_radius = circles[:, 2]
        self.circle_height = np.asarray(world.circle_height, dtype=np.float64).reshape(-1)

    def cast(
        self,
        origin_xy: np.ndarray,
        angles_rad: np.ndarray,
        max_range_m: float,
        min_height_m: float = 0.0,
    ) -> RayHits:
        """Cast rays from `origin_xy` ((2,) one origin, or (K, 2) one per ray) along world-frame
        `angles_rad` (K,), ignoring surfaces lower than `min_height_m`. Hits beyond
        `max_range_m` are reported as inf."""
        angles = np.asarray(angles_rad, dtype=np.float64).reshape(-1)
        directions = np.stack([np.cos(angles), np.sin(angles)], axis=1)  # (K, 2)
        origins = np.broadcast_to(np.asarray(origin_xy, dtype=np.float64), directions.shape)

        best = np.full(angles.shape, np.inf)
        best_cos = np.full(angles.shape, np.nan)

        seg_mask = self.segment_height >= min_height_m
        if seg_mask.any():
            distance, cos_incidence = self._cast_segments(origins, directions, seg_mask)
            closer = distance < best
            best = np.where(closer, distance, best)
            best_cos = np.where(closer, cos_incidence, best_cos)

        circ_mask = self.circle_height >= min_height_m
        if circ_mask.any():
            distance, cos_incidence = self._cast_circles(origins, directions, circ_mask)
            closer = distance < best
            best = np.where(closer, distance, best)
            best_cos = np.where(closer, cos_incidence, best_cos)

        out_of_range = best > max_range_m
        best[out_of_range] = np.inf
        best_cos[out_of_range] = np.nan
        return RayHits(distance_m=best, incidence_rad=np.arccos(np.clip(best_cos, 0.0, 1.0)))

    def _cast_segments(
        self, origins: np.ndarray, directions: np.ndarray, mask: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        start = self.segment_start[mask]  # (N, 2)
        edge = self.segment_vector[mask]
        normal = self.segment_normal[mask]
        dx, dy = directions[:, 0:1], directions[:, 1:2]  # (K, 1)
        wx = start[None, :, 0] - origins[:, 0:1]  # (K, N)
        wy = start[None, :, 1] - origins[:, 1:2]
        denom = dx * edge[None, :, 1] - dy * edge[None, :, 0]
        parallel = np.abs(denom) < _PARALLEL_EPS
        safe = np.where(parallel, 1.0, denom)
        t = (wx * edge[None, :, 1] - wy * edge[None, :, 0]) / safe  # along the ray [m]
        s = (wx * dy - wy * dx) / safe  # along the segment [0..1]
        valid = ~parallel & (t >= 0.0) & (s >= 0.0) & (s <= 1.0)
        t = np.where(valid, t, np.inf)
        nearest = np.argmin(t, axis=1)
        rows = np.arange(t.shape[0])
        distance = t[rows, nearest]
        hit_normal = normal[nearest]
        cos_incidence = np.abs(np.sum(hit_normal * directions, axis=1))
        return distance, cos_incidence

    def _cast_circles(
        self, origins: np.ndarray, directions: np.ndarray, mask: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        centre = self.circle_centre[mask]  # (M, 2)
        radius = self.circle_radius[mask]
        fx = origins[:, 0:1] - centre[None, :, 0]  # (K, M)
        fy = origins[:, 1:2] - centre[None, :, 1]
        b = fx * directions[:, 0:1] + fy * directions[:, 1:2]
        c = fx * fx + fy * fy - radius[None, :] ** 2
        disc = b * b - c
        root = np.sqrt(np.maximum(disc, 0.0))
        t = -b - root
        inside = c < 0.0  # origin inside a cylinder: it is touching, range 0
        t = np.where(inside, 0.0, t)
        valid = (disc >= 0.0) & (t >= 0.0)
        t = np.where(valid, t, np.inf)
        nearest = np.argmin(t, axis=1)
        rows = np.arange(t.shape[0])
        distance = t[rows, nearest]
        hit = origins + directions * np.where(np.isfinite(distance), distance, 0.0)[:, None]
        outward = hit - centre[nearest]
        outward /= np.maximum(np.hypot(outward[:, 0], outward[:, 1]), 1e-12)[:, None]
        cos_incidence = np.abs(np.sum(outward * directions, axis=1))
        return distance, cos_incidence

    def penetrations(
        self, centre_x: float, centre_y: float, radius_m: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """Surfaces a disc of `radius_m` at (centre_x, centre_y) overlaps.

        Returns (push, angle): `push` (P, 2) the world-frame vectors that move the disc out of
        each overlapping surface, `angle` (P,) the world-frame direction from the centre to each
        touching surface [rad]. Empty arrays when nothing touches.
        """
        centre = np.array([centre_x, centre_y])
        pushes: list[np.ndarray] = []
        # Closest point on each segment to the centre.
        rel = centre - self.segment_start
        along = np.clip(
            np.sum(rel * self.segment_vector, axis=1) / self.segment_length_sq, 0.0, 1.0
        )
        closest = self.segment_start + along[:, None] * self.segment_vector
        away = centre - closest
        gap = np.hypot(away[:, 0], away[:, 1])
        touching = gap < radius_m
        if touching.any():
            g = np.maximum(gap[touching], 1e-9)
            pushes.append(away[touching] / g[:, None] * (radius_m - g)[:, None])
        away_c = centre - self.circle_centre
        gap_c = np.hypot(away_c[:, 0], away_c[:, 1])
        overlap = radius_m + self.circle_radius - gap_c
        touching_c = overlap > 0.0
        if touching_c.any():
            g = np.maximum(gap_c[touching_c], 1e-9)
            pushes.append(away_c[touching_c] / g[:, None] * overlap[touching_c][:, None])
        if not pushes:
            return np.zeros((0, 2)), np.zeros(0)
        push = np.concatenate(pushes)
        angle = np.arctan2(-push[:, 1], -push[:, 0])
        return push, angle

    def clearance(self, x: float, y: float) -> float:
        """Distance [m] from the point (x, y) to the nearest surface (inf in an empty world)."""
        point = np.array([x, y])
        nearest = np.inf
        if len(self.segment_start):
            rel = point - self.segment_start
            along = np.clip(
                np.sum(rel * self.segment_vector, axis=1) / self.segment_length_sq, 0.0, 1.0
            )
            away = rel - along[:, None] * self.segment_vector
            nearest = float(np.min(np.hypot(away[:, 0], away[:, 1])))
        if len(self.circle_centre):
            away_c = point - self.circle_centre
            gaps = np.hypot(away_c[:, 0], away_c[:, 1]) - self.circle_radius
            nearest = min(nearest, float(np.min(gaps)))
        return nearest
