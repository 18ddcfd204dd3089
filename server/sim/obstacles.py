"""Solid world geometry prepared for fast queries: ray casts for the range sensors, and the
distance from a circular robot body to the nearest surfaces for collisions.

Surfaces are the world's wall/box segments and cylinders (plants, posts); each has a height, so a
sensor that looks at a horizontal slice above the floor (the TurtleBot's depth scan at ~0.45 m,
003_4f92d1fa0a49ddae.txt section 5) can ignore what is lower than its slice.

Ray casting, and why it culls. The plain way is to intersect every ray with every surface
(`_cast_dense`: one batch of rays x surfaces arrays). A 429-beam scan against the 84 plants of
`crop_rows` is then 36k ray-circle tests, ~2 ms a scan, while each beam can only meet the few
plants in its direction. So a scan from one origin (`_cast_culled`) first drops surfaces lower
than the slice or farther than the range, then gives each remaining surface the interval of
bearings it covers as seen from the origin: a circle at bearing phi and distance d spans
phi +- asin(r/d); a segment spans the shorter arc between its endpoints' bearings (the whole
turn when the origin is on it). The ray bearings are sorted once, so `searchsorted` finds the rays
inside each interval (wrap at +-pi handled by searching a copy shifted by 2 pi), and only those
(ray, surface) pairs are intersected, with the same arithmetic as the dense path. The nearest hit
per ray wins; ties go to the same surface as in the dense path (segments first, then lower
index), so the two paths agree exactly. Intervals are widened by a nano-radian, so rounding
can only add candidates (which then miss), never drop a hit. The crop-field scan drops from ~2.4 ms
to ~0.35 ms (`python3 -m bench.bench_scans`).

Fallback: casts with one origin per ray ((K, 2) origins), casts from inside a cylinder (range 0
for every ray: a degenerate case where interval culling buys nothing) and small casts (a few rays
or surfaces, where culling's fixed cost exceeds its savings) use `_cast_dense`, which is also what
the tests compare the culled path against. The smallest casts (an ultrasonic cone, an IR beam:
up to `_FEW_MAX_PAIRS` ray x surface pairs) go through `raycast_few`, a plain Python loop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from server.sim.geometry import distance_to_nearest, offsets_from_segments, segment_arrays
from server.sim.raycast_few import (
    Circle,
    Segment,
    cast_few,
    clearance_few,
    contacts_few,
)
from server.sim.world import World

_PARALLEL_EPS = 1e-12  # [m^2] |cross(d, e)| below this: ray parallel to the segment, no hit
_ANGLE_MARGIN_RAD = 1e-9  # culling intervals are widened by this to absorb rounding
_ON_SEGMENT_SPAN_RAD = math.pi - 1e-6  # an endpoint arc this wide: origin on the segment
_RANGE_MARGIN_M = 1e-6  # surfaces farther than max range + this are culled
_TWO_PI = 2.0 * math.pi
# Rays x surfaces up to which the dense path is no slower than culling's fixed cost (~60 numpy
# calls): measured crossover ~3000-5000 pairs (e.g. 60 rays in the 49-surface office).
_DENSE_MAX_PAIRS = 4000
# Up to this many ray x surface pairs, a plain Python loop beats numpy's per-call overhead.
_FEW_MAX_PAIRS = 160
_FEW_MAX_SURFACES = 64  # contact queries below this many surfaces go through raycast_few


@dataclass(frozen=True, slots=True)
class RayHits:
    """Result of a ray cast, one entry per ray.

    `distance_m` is the range to the first surface (inf where nothing is hit within range);
    `incidence_rad` is the angle between the ray and the surface normal at the hit (0 = the ray
    meets the surface head-on, pi/2 = grazing; nan where nothing is hit).
    """

    distance_m: np.ndarray
    incidence_rad: np.ndarray


def _wrap_rad(angle_rad: np.ndarray) -> np.ndarray:
    """Angles wrapped into [-pi, pi]."""
    return np.mod(angle_rad + math.pi, _TWO_PI) - math.pi


# (t, ray, surface rank) of no candidate hits.
_NO_HITS = (np.zeros(0), np.zeros(0, dtype=np.intp), np.zeros(0, dtype=np.intp))


@dataclass(frozen=True, slots=True)
class _SortedRays:
    """The bearings of one cast's rays, sorted, for finding the rays inside arcs of bearing.

    `bearings_twice` holds the sorted bearings in [-pi, pi] followed by the same + 2 pi, so an
    arc that crosses +-pi is one contiguous run; `order` maps sorted positions to ray indices.
    """

    bearings_twice: np.ndarray
    order: np.ndarray

    def in_arcs(self, low_rad: np.ndarray, width_rad: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every (arc, ray) pair where the ray's bearing lies in the arc [low, low + width]."""
        ray_count = self.order.size
        low = _wrap_rad(low_rad)
        first = np.searchsorted(self.bearings_twice, low, "left")
        last = np.searchsorted(self.bearings_twice, low + width_rad, "right")
        count = np.minimum(last - first, ray_count)  # a full-turn arc holds each ray once
        arc = np.repeat(np.arange(count.size), count)
        run_start = np.repeat(first - (np.cumsum(count) - count), count)
        return arc, self.order[(run_start + np.arange(arc.size)) % ray_count]


class Obstacles:
    """The world's solid surfaces as flat arrays, built once per simulation."""

    def __init__(self, world: World) -> None:
        segments = np.asarray(world.segments, dtype=np.float64).reshape(-1, 4)
        circles = np.asarray(world.circles, dtype=np.float64).reshape(-1, 3)
        self.segment_start, self.segment_vector, self.segment_length_sq = segment_arrays(segments)
        lengths = np.hypot(self.segment_vector[:, 0], self.segment_vector[:, 1])
        # Unit normals; the sign does not matter because incidence uses |cos|.
        self.segment_normal = (
            np.stack([-self.segment_vector[:, 1], self.segment_vector[:, 0]], axis=1)
            / np.maximum(lengths, 1e-9)[:, None]
        )
        self.segment_height = np.asarray(world.segment_height, dtype=np.float64).reshape(-1)
        self.circle_centre = circles[:, 0:2]
        self.circle_radius = circles[:, 2]
        self.circle_height = np.asarray(world.circle_height, dtype=np.float64).reshape(-1)
        # One contiguous 1-D array per coordinate for the culled cast: gathering pairs from these
        # is several times faster than gathering rows of the (N, 2) arrays.
        self._start_x, self._start_y, self._end_x, self._end_y = np.array(segments.T)
        self._edge_x, self._edge_y = np.array(self.segment_vector.T)
        self._normal_x, self._normal_y = np.array(self.segment_normal.T)
        self._circle_x, self._circle_y = np.array(self.circle_centre.T)
        # The same surfaces as plain tuples for `cast_few`.
        self._few_segments = [
            Segment(*row)
            for row in np.column_stack(
                [self.segment_start, self.segment_vector, self.segment_normal, self.segment_height]
            ).tolist()
        ]
        # (centre x, centre y, half length) [m] of each segment: `cast_small` leaves out those
        # wholly out of reach.
        self._few_segment_bounds = [
            (seg.start_x + seg.edge_x / 2, seg.start_y + seg.edge_y / 2,
             math.hypot(seg.edge_x, seg.edge_y) / 2)
            for seg in self._few_segments
        ]  # fmt: skip
        # Contact queries in plain Python pay off up to this many surfaces.
        self._few_surfaces = len(segments) + len(circles) <= _FEW_MAX_SURFACES
        self._few_circles = [
            Circle(x, y, r * r, h)
            for x, y, r, h in np.column_stack(
                [self.circle_centre, self.circle_radius, self.circle_height]
            ).tolist()
        ]

    def cast_small(
        self, origin_x: float, origin_y: float, angles_rad: list[float], max_range_m: float
    ) -> tuple[list[float], list[float]] | None:
        """`cast` from one origin in plain Python lists, for a sensor that samples a few rays
        often: per ray the distance (inf beyond `max_range_m`) and the cosine of the incidence
        angle (nan where nothing is hit). None when the world is too large for the loop: use
        `cast` then."""
        surface_count = self.segment_height.size + self.circle_height.size
        if len(angles_rad) * surface_count > _FEW_MAX_PAIRS:
            return None
        # A surface whose nearest point is beyond the range cannot give a reading (a ray meets it
        # further still): leaving it out changes no result, in order, and skips most of a room.
        hypot = math.hypot
        reach_m = max_range_m + _RANGE_MARGIN_M  # rounding in the bound must not cut a hit
        segments = [
            segment
            for segment, (centre_x, centre_y, half_length) in zip(
                self._few_segments, self._few_segment_bounds, strict=True
            )
            if hypot(centre_x - origin_x, centre_y - origin_y) - half_length <= reach_m
        ]
        circles = [
            circle
            for circle in self._few_circles
            if hypot(circle.x - origin_x, circle.y - origin_y) - math.sqrt(circle.radius_sq)
            <= reach_m
        ]
        return cast_few(segments, circles, origin_x, origin_y, angles_rad, max_range_m, 0.0)

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
        origin = np.asarray(origin_xy, dtype=np.float64)
        angles = np.asarray(angles_rad, dtype=np.float64).reshape(-1)
        surface_count = self.segment_height.size + self.circle_height.size
        if origin.shape == (2,) and angles.size * surface_count <= _FEW_MAX_PAIRS:
            distances, cosines = cast_few(
                self._few_segments,
                self._few_circles,
                float(origin[0]),
                float(origin[1]),
                angles.tolist(),
                max_range_m,
                min_height_m,
            )
            cos_incidence = np.array(cosines)
            return RayHits(
                distance_m=np.array(distances),
                incidence_rad=np.arccos(np.clip(cos_incidence, 0.0, 1.0)),
            )
        if origin.shape == (2,) and angles.size * surface_count > _DENSE_MAX_PAIRS:
            return self._cast_culled(origin, angles, max_range_m, min_height_m)
        return self._cast_dense(origin, angles, max_range_m, min_height_m)

    def _cast_culled(
        self, origin: np.ndarray, angles: np.ndarray, max_range_m: float, min_height_m: float
    ) -> RayHits:
        """`cast` from one origin, intersecting only the (ray, surface) pairs whose bearings
        overlap (see the module docstring). Falls back to `_cast_dense` inside a cylinder."""
        dx, dy = np.cos(angles), np.sin(angles)
        bearing = np.arctan2(dy, dx)
        order = np.argsort(bearing)
        rays = _SortedRays(np.concatenate([bearing[order], bearing[order] + _TWO_PI]), order)
        reach_m = max_range_m + _RANGE_MARGIN_M

        circle_hits = self._circle_candidates(origin, dx, dy, rays, reach_m, min_height_m)
        if circle_hits is None:
            return self._cast_dense(origin, angles, max_range_m, min_height_m)
        segment_hits = self._segment_candidates(origin, dx, dy, rays, reach_m, min_height_m)
        t, ray, rank = (
            np.concatenate(parts) for parts in zip(segment_hits, circle_hits, strict=True)
        )
        in_range = t <= max_range_m
        t, ray, rank = t[in_range], ray[in_range], rank[in_range]

        distance = np.full(angles.shape, np.inf)
        np.minimum.at(distance, ray, t)
        nearest = t == distance[ray]
        # Equal distances go to the lowest rank (segments by index, then circles), as the
        # first-minimum rule of `_cast_dense` does.
        winning_rank = np.full(angles.shape, np.iinfo(np.int64).max)
        np.minimum.at(winning_rank, ray[nearest], rank[nearest])
        winner = nearest & (rank == winning_rank[ray])  # one per ray: a surface meets it once
        ray, t, rank = ray[winner], t[winner], rank[winner]
        cos_incidence = np.full(angles.shape, np.nan)
        cos_incidence[ray] = self._cos_incidence(origin, dx[ray], dy[ray], t, rank)
        return RayHits(distance_m=distance, incidence_rad=np.arccos(np.clip(cos_incidence, 0, 1)))

    def _segment_candidates(
        self,
        origin: np.ndarray,
        dx: np.ndarray,
        dy: np.ndarray,
        rays: _SortedRays,
        reach_m: float,
        min_height_m: float,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(t, ray, segment index) of every ray-segment hit among the culled pairs."""
        seg = np.flatnonzero(self.segment_height >= min_height_m)
        if seg.size and np.isfinite(reach_m):
            seg = seg[self._away_from_segments(origin, seg)[1] <= reach_m]
        if not seg.size:
            return _NO_HITS
        wx, wy = self._start_x[seg] - origin[0], self._start_y[seg] - origin[1]
        start_bearing = np.arctan2(wy, wx)
        end_bearing = np.arctan2(self._end_y[seg] - origin[1], self._end_x[seg] - origin[0])
        span = _wrap_rad(end_bearing - start_bearing)
        low = np.minimum(start_bearing, start_bearing + span) - _ANGLE_MARGIN_RAD
        width = np.abs(span) + 2.0 * _ANGLE_MARGIN_RAD
        width[np.abs(span) >= _ON_SEGMENT_SPAN_RAD] = _TWO_PI
        which, ray = rays.in_arcs(low, width)
        index = seg[which]
        # The same arithmetic as `_dense_segments`, pair by pair.
        rdx, rdy = dx[ray], dy[ray]
        ex, ey = self._edge_x[index], self._edge_y[index]
        wx, wy = wx[which], wy[which]
        denom = rdx * ey - rdy * ex
        parallel = np.abs(denom) < _PARALLEL_EPS
        safe = np.where(parallel, 1.0, denom)
        t = (wx * ey - wy * ex) / safe  # along the ray [m]
        s = (wx * rdy - wy * rdx) / safe  # along the segment [0..1]
        valid = ~parallel & (t >= 0.0) & (s >= 0.0) & (s <= 1.0)
        return t[valid], ray[valid], index[valid]

    def _circle_candidates(
        self,
        origin: np.ndarray,
        dx: np.ndarray,
        dy: np.ndarray,
        rays: _SortedRays,
        reach_m: float,
        min_height_m: float,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """(t, ray, segment count + circle index) of every ray-circle hit among the culled pairs,
        or None when the origin is inside (or on) a cylinder."""
        circ = np.flatnonzero(self.circle_height >= min_height_m)
        if not circ.size:
            return _NO_HITS
        fx = origin[0] - self._circle_x[circ]
        fy = origin[1] - self._circle_y[circ]
        c = fx * fx + fy * fy - self.circle_radius[circ] ** 2  # as in `_dense_circles`
        if np.any(c <= 0.0):
            return None
        centre_distance = np.sqrt(fx * fx + fy * fy)
        near = centre_distance - self.circle_radius[circ] <= reach_m
        circ, fx, fy, c, centre_distance = (a[near] for a in (circ, fx, fy, c, centre_distance))
        if not circ.size:
            return _NO_HITS
        half = np.arcsin(np.minimum(self.circle_radius[circ] / centre_distance, 1.0))
        half += _ANGLE_MARGIN_RAD
        which, ray = rays.in_arcs(np.arctan2(-fy, -fx) - half, 2.0 * half)
        b = fx[which] * dx[ray] + fy[which] * dy[ray]
        disc = b * b - c[which]
        t = -b - np.sqrt(np.maximum(disc, 0.0))
        valid = (disc >= 0.0) & (t >= 0.0)
        return t[valid], ray[valid], self.segment_height.size + circ[which[valid]]

    def _cos_incidence(
        self, origin: np.ndarray, dx: np.ndarray, dy: np.ndarray, t: np.ndarray, rank: np.ndarray
    ) -> np.ndarray:
        """|cos| of the angle between each ray and the normal of the surface it hit (`rank`:
        segment index, or segment count + circle index)."""
        cos = np.empty(t.shape)
        on_segment = rank < self.segment_height.size
        if on_segment.any():
            index = rank[on_segment]
            nx, ny = self._normal_x[index], self._normal_y[index]
            cos[on_segment] = np.abs(nx * dx[on_segment] + ny * dy[on_segment])
        on_circle = ~on_segment
        if not on_circle.any():
            return cos
        index = rank[on_circle] - self.segment_height.size
        cdx, cdy, ct = dx[on_circle], dy[on_circle], t[on_circle]
        outward_x = origin[0] + cdx * ct - self._circle_x[index]
        outward_y = origin[1] + cdy * ct - self._circle_y[index]
        norm = np.maximum(np.hypot(outward_x, outward_y), 1e-12)
        cos[on_circle] = np.abs(outward_x / norm * cdx + outward_y / norm * cdy)
        return cos

    def _cast_dense(
        self, origin_xy: np.ndarray, angles: np.ndarray, max_range_m: float, min_height_m: float
    ) -> RayHits:
        """`cast` by intersecting every ray with every surface: the general path (one origin per
        ray, origin inside a cylinder) and the reference the culled path is tested against."""
        directions = np.stack([np.cos(angles), np.sin(angles)], axis=1)  # (K, 2)
        origins = np.broadcast_to(np.asarray(origin_xy, dtype=np.float64), directions.shape)

        best = np.full(angles.shape, np.inf)
        best_cos = np.full(angles.shape, np.nan)

        seg_mask = self.segment_height >= min_height_m
        if seg_mask.any():
            distance, cos_incidence = self._dense_segments(origins, directions, seg_mask)
            closer = distance < best
            best = np.where(closer, distance, best)
            best_cos = np.where(closer, cos_incidence, best_cos)

        circ_mask = self.circle_height >= min_height_m
        if circ_mask.any():
            distance, cos_incidence = self._dense_circles(origins, directions, circ_mask)
            closer = distance < best
            best = np.where(closer, distance, best)
            best_cos = np.where(closer, cos_incidence, best_cos)

        out_of_range = best > max_range_m
        best[out_of_range] = np.inf
        best_cos[out_of_range] = np.nan
        return RayHits(distance_m=best, incidence_rad=np.arccos(np.clip(best_cos, 0.0, 1.0)))

    def _dense_segments(
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

    def _dense_circles(
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
        push, angle, _ = self.contacts(centre_x, centre_y, radius_m)
        return push, angle

    def contacts(
        self, centre_x: float, centre_y: float, radius_m: float
    ) -> tuple[np.ndarray, np.ndarray, float]:
        """`penetrations` and `clearance` of the same centre in one pass over the surfaces:
        (push, angle, distance [m] from the centre to the nearest surface)."""
        if self._few_surfaces:
            few, nearest = contacts_few(
                self._few_segments, self._few_circles, centre_x, centre_y, radius_m
            )
            if not few:
                return np.zeros((0, 2)), np.zeros(0), nearest
            push = np.array(few)
            return push, np.arctan2(-push[:, 1], -push[:, 0]), nearest
        centre = np.array([centre_x, centre_y])
        pushes: list[np.ndarray] = []
        nearest = math.inf
        if self.segment_height.size:
            away, gap = self._away_from_segments(centre)
            nearest = float(np.min(gap))
            touching = gap < radius_m
            if touching.any():
                g = np.maximum(gap[touching], 1e-9)
                pushes.append(away[touching] / g[:, None] * (radius_m - g)[:, None])
        if self.circle_radius.size:
            away_c = centre - self.circle_centre
            gap_c = np.hypot(away_c[:, 0], away_c[:, 1])
            nearest = min(nearest, float(np.min(gap_c - self.circle_radius)))
            overlap = radius_m + self.circle_radius - gap_c
            touching_c = overlap > 0.0
            if touching_c.any():
                g = np.maximum(gap_c[touching_c], 1e-9)
                pushes.append(away_c[touching_c] / g[:, None] * overlap[touching_c][:, None])
        if not pushes:
            return np.zeros((0, 2)), np.zeros(0), nearest
        push = np.concatenate(pushes)
        angle = np.arctan2(-push[:, 1], -push[:, 0])
        return push, angle, nearest

    def clearance(self, x: float, y: float) -> float:
        """Distance [m] from the point (x, y) to the nearest surface (inf in an empty world)."""
        if self._few_surfaces:
            return clearance_few(self._few_segments, self._few_circles, x, y)
        return distance_to_nearest(
            np.array([x, y]),
            (self.segment_start, self.segment_vector, self.segment_length_sq),
            self.circle_centre,
            self.circle_radius,
        )

    def _away_from_segments(
        self, point: np.ndarray, index: np.ndarray | slice = slice(None)
    ) -> tuple[np.ndarray, np.ndarray]:
        """(N, 2) vectors from the closest point of each segment (or of segments `index`) to
        `point`, and their lengths (N,) [m]."""
        return offsets_from_segments(
            point,
            self.segment_start[index],
            self.segment_vector[index],
            self.segment_length_sq[index],
        )
