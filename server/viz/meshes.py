"""Unit meshes and rotations the drawings share: a box and a z-axis cylinder built here, so every
shape's orientation is ours to know (viser's own primitives follow three.js axes), and batched
instances scale them per axis.

Faces wind counter-clockwise seen from outside (their normals point out), as three.js culls.
"""

from __future__ import annotations

import math

import numpy as np

CYLINDER_SEGMENTS = 24  # [-] sides of a drawn cylinder: round at any distance the view allows


def yaw_wxyz(yaw_rad: float) -> tuple[float, float, float, float]:
    """The quaternion (w, x, y, z) of a turn by `yaw_rad` about +z."""
    half = 0.5 * float(yaw_rad)
    return (math.cos(half), 0.0, 0.0, math.sin(half))


def yaw_wxyzs(yaws_rad: np.ndarray) -> np.ndarray:
    """(N, 4) quaternions (w, x, y, z) of turns about +z."""
    half = 0.5 * np.asarray(yaws_rad, dtype=np.float64)
    zeros = np.zeros_like(half)
    return np.stack([np.cos(half), zeros, zeros, np.sin(half)], axis=1)


def unit_box() -> tuple[np.ndarray, np.ndarray]:
    """A 1 m cube centred on the origin: (8, 3) vertices, (12, 3) faces."""
    corners = np.array(
        [[x, y, z] for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)],
        dtype=np.float32,
    )
    # Corner index = x + 2 y + 4 z (each 0 or 1); two triangles per side, outward normals.
    faces = np.array(
        [
            [0, 2, 1], [1, 2, 3],  # bottom (-z)
            [4, 5, 6], [5, 7, 6],  # top (+z)
            [0, 1, 4], [1, 5, 4],  # front (-y)
            [2, 6, 3], [3, 6, 7],  # back (+y)
            [0, 4, 2], [2, 4, 6],  # left (-x)
            [1, 3, 5], [3, 7, 5],  # right (+x)
        ],
        dtype=np.uint32,
    )  # fmt: skip
    return corners, faces


def unit_cylinder(segments: int = CYLINDER_SEGMENTS) -> tuple[np.ndarray, np.ndarray]:
    """A cylinder of radius 1 m and height 1 m about +z, centred on the origin."""
    angles = np.linspace(0.0, 2.0 * math.pi, segments, endpoint=False)
    ring = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    bottom = np.column_stack([ring, np.full(segments, -0.5)])
    top = np.column_stack([ring, np.full(segments, 0.5)])
    centres = np.array([[0.0, 0.0, -0.5], [0.0, 0.0, 0.5]])
    vertices = np.vstack([bottom, top, centres]).astype(np.float32)
    low_centre, high_centre = 2 * segments, 2 * segments + 1
    faces = []
    for i in range(segments):
        j = (i + 1) % segments
        faces += [[i, j, segments + i], [j, segments + j, segments + i]]  # side
        faces += [[low_centre, j, i], [high_centre, segments + i, segments + j]]  # caps
    return vertices, np.array(faces, dtype=np.uint32)


def transformed(
    vertices: np.ndarray,
    scale: tuple[float, float, float],
    offset: tuple[float, float, float] = (0.0, 0.0, 0.0),
    swap_yz: bool = False,
) -> np.ndarray:
    """Vertices scaled per axis, optionally turned so +z becomes +y (a wheel's axle), then
    moved by `offset` [m]."""
    out = vertices * np.asarray(scale, dtype=np.float32)
    if swap_yz:
        out = out[:, [0, 2, 1]] * np.array([1.0, -1.0, 1.0], dtype=np.float32)
    return (out + np.asarray(offset, dtype=np.float32)).astype(np.float32)
