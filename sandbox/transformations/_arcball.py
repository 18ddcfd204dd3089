"""The virtual trackball of tf.transformations (K. Shoemake, "Arcball rotation control",
Graphics Gems IV (1994) pp. 175-192): window points map onto a unit sphere, and a drag from
one sphere point to another is the rotation between them."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ._rotations import (
    quaternion_from_matrix,
    quaternion_matrix,
    quaternion_multiply,
    quaternion_slerp,
)
from ._vectors import EPS, unit_vector


def arcball_map_to_sphere(point: Any, center: Any, radius: float) -> np.ndarray:
    """The unit-sphere point under window point `point` (window y grows downwards)."""
    v = np.array(
        [(point[0] - center[0]) / radius, (center[1] - point[1]) / radius, 0.0], dtype=np.float64
    )
    planar = float(v[0] * v[0] + v[1] * v[1])
    if planar > 1.0:  # outside the ball: the nearest point on its rim
        return v / math.sqrt(planar)
    v[2] = math.sqrt(1.0 - planar)
    return v


def arcball_constrain_to_axis(point: Any, axis: Any) -> np.ndarray:
    """The sphere point nearest to `point` on the great circle perpendicular to `axis`."""
    v = np.array(point, dtype=np.float64)
    a = np.array(axis, dtype=np.float64)
    v -= a * float(a @ v)
    length = math.sqrt(float(v @ v))
    if length > EPS:
        return (-v if v[2] < 0.0 else v) / length
    if a[2] == 1.0:
        return np.array([1.0, 0.0, 0.0])
    return unit_vector([-a[1], a[0], 0.0])


def arcball_nearest_axis(point: Any, axes: Any) -> Any:
    """The axis of `axes` whose great circle passes nearest to `point`."""
    p = np.asarray(point, dtype=np.float64)
    return max(axes, key=lambda axis: float(arcball_constrain_to_axis(p, axis) @ p))


class Arcball:
    """Virtual trackball: place(), then down() and drag() with window points; matrix()."""

    def __init__(self, initial: Any = None) -> None:
        self._axis: Any = None
        self._axes: Any = None
        self._radius = 1.0
        self._center = [0.0, 0.0]
        self._vdown = np.array([0.0, 0.0, 1.0])
        self._constrain = False
        if initial is None:
            start = np.array([0.0, 0.0, 0.0, 1.0])
        else:
            given = np.array(initial, dtype=np.float64)
            if given.shape == (4, 4):
                start = quaternion_from_matrix(given)
            elif given.shape == (4,):
                start = given / math.sqrt(float(given @ given))
            else:
                raise ValueError("Arcball(initial=...) takes a quaternion or a 4x4 matrix")
        self._qdown = self._qnow = self._qpre = start

    def place(self, center: Any, radius: float) -> None:
        """Centre (window coordinates) and radius of the ball."""
        self._radius = float(radius)
        self._center = [center[0], center[1]]

    def setaxes(self, *axes: Any) -> None:
        """Axes to which drags may be constrained."""
        self._axes = [unit_vector(axis) for axis in axes] if axes else None

    def setconstrain(self, constrain: bool) -> None:
        self._constrain = bool(constrain)

    def getconstrain(self) -> bool:
        return self._constrain

    def down(self, point: Any) -> None:
        """Start a drag at window point `point`."""
        self._vdown = arcball_map_to_sphere(point, self._center, self._radius)
        self._qdown = self._qpre = self._qnow
        self._axis = None
        if self._constrain and self._axes is not None:
            self._axis = arcball_nearest_axis(self._vdown, self._axes)
            self._vdown = arcball_constrain_to_axis(self._vdown, self._axis)

    def drag(self, point: Any) -> None:
        """Continue the drag to window point `point`."""
        vnow = arcball_map_to_sphere(point, self._center, self._radius)
        if self._axis is not None:
            vnow = arcball_constrain_to_axis(vnow, self._axis)
        self._qpre = self._qnow
        turn = np.cross(self._vdown, vnow)
        if float(turn @ turn) < EPS:
            self._qnow = self._qdown
        else:
            drag = [turn[0], turn[1], turn[2], float(self._vdown @ vnow)]
            self._qnow = quaternion_multiply(drag, self._qdown)

    def next(self, acceleration: float = 0.0) -> None:
        """Keep turning the way the last drag went."""
        q = quaternion_slerp(self._qpre, self._qnow, 2.0 + acceleration, False)
        self._qpre, self._qnow = self._qnow, q

    def matrix(self) -> np.ndarray:
        """The current rotation as a 4x4 matrix."""
        return quaternion_matrix(self._qnow)
