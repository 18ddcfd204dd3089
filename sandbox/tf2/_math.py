"""The little rigid-body algebra tf2 needs, on plain tuples: quaternions (x, y, z, w) and
vectors (x, y, z). Pure Python on purpose: a lookup composes a handful of transforms, for
which numpy's per-call overhead would cost more than the arithmetic."""

from __future__ import annotations

import math

Vector = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]
Pose = tuple[Vector, Quaternion]  # (translation, rotation): the transform x -> R x + t

IDENTITY: Pose = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def multiply(a: Quaternion, b: Quaternion) -> Quaternion:
    """The Hamilton product a * b (rotate by b, then by a)."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def conjugate(q: Quaternion) -> Quaternion:
    """The inverse rotation (tf2's Quaternion::inverse is the conjugate too)."""
    return (-q[0], -q[1], -q[2], q[3])


def rotate(q: Quaternion, v: Vector) -> Vector:
    """v rotated by q, i.e. q v q^-1."""
    x, y, z, _ = multiply(multiply(q, (v[0], v[1], v[2], 0.0)), conjugate(q))
    return (x, y, z)


def compose(outer: Pose, inner: Pose) -> Pose:
    """The transform that applies `inner`, then `outer`."""
    (to, ro), (ti, ri) = outer, inner
    moved = rotate(ro, ti)
    return ((moved[0] + to[0], moved[1] + to[1], moved[2] + to[2]), multiply(ro, ri))


def invert(pose: Pose) -> Pose:
    translation, rotation = pose
    back = conjugate(rotation)
    x, y, z = rotate(back, translation)
    return ((-x, -y, -z), back)


def lerp(a: Vector, b: Vector, ratio: float) -> Vector:
    return (
        a[0] + (b[0] - a[0]) * ratio,
        a[1] + (b[1] - a[1]) * ratio,
        a[2] + (b[2] - a[2]) * ratio,
    )


def slerp(a: Quaternion, b: Quaternion, ratio: float) -> Quaternion:
    """Spherical interpolation from a (ratio 0) to b (ratio 1) the short way round, as tf2's
    Quaternion::slerp does."""
    dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
    norms = math.sqrt(sum(c * c for c in a) * sum(c * c for c in b))
    if norms == 0.0:
        return a
    if dot < 0.0:  # q and -q are the same rotation: take the shorter arc
        b, dot = (-b[0], -b[1], -b[2], -b[3]), -dot
    half_angle = math.acos(min(1.0, dot / norms))
    if half_angle == 0.0:
        return a
    scale = 1.0 / math.sin(half_angle)
    wa = math.sin((1.0 - ratio) * half_angle) * scale
    wb = math.sin(ratio * half_angle) * scale
    return (
        a[0] * wa + b[0] * wb,
        a[1] * wa + b[1] * wb,
        a[2] * wa + b[2] * wb,
        a[3] * wa + b[3] * wb,
    )
