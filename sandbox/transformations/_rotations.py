"""Rotations in tf.transformations: Euler angles (all 24 conventions), quaternions, axis-angle.

Quaternions are [x, y, z, w], as in the module ROS ships. Euler conventions are named as there:
'sxyz' applies rotations about the static x, then y, then z axes (M = Rz(ak) Ry(aj) Rx(ai));
'rxyz' about the rotating x, then the new y, then the new z (M = Rx(ai) Ry(aj) Rz(ak)). The
same conventions can be given as 4-tuples (inner axis, parity, repetition, frame), which this
module derives from the strings rather than listing them.

Sources: K. Shoemake, "Euler angle conversion", Graphics Gems IV (1994) pp. 222-229, for the
naming and the angle ranges (middle angle in [-pi/2, pi/2] for Tait-Bryan sequences, [0, pi]
or [-pi, 0] for proper Euler ones; in gimbal lock the angle applied last about the static axes
is 0);
S. W. Shepperd, "Quaternion from rotation matrix", J. Guidance and Control 1(3) (1978) for the
matrix-to-quaternion branch choice; K. Shoemake, "Uniform random rotations", Graphics Gems III
(1992) pp. 124-132 for random_quaternion; Rodrigues' formula for rotation_matrix.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ._vectors import EPS, as_matrix, as_vector, unit_vector

_AXIS_INDEX = {"x": 0, "y": 1, "z": 2}


def _encode(axes: str) -> tuple[int, int, int, int]:
    """The 4-tuple form of an axes string (the encoding of Shoemake's paper)."""
    first, second, third = (_AXIS_INDEX[letter] for letter in axes[1:])
    if axes[0] == "r":  # a rotating sequence is the static one read backwards
        first, third = third, first
    parity = 0 if (second - first) % 3 == 1 else 1
    return (first, parity, int(first == third), int(axes[0] == "r"))


_AXES = [
    frame + a + b + c
    for frame in "sr"
    for a in "xyz"
    for b in "xyz"
    for c in "xyz"
    if a != b and b != c
]
_AXES2TUPLE = {axes: _encode(axes) for axes in _AXES}
_TUPLE2AXES = {code: axes for axes, code in _AXES2TUPLE.items()}
_NEXT_AXIS = [1, 2, 0, 1]  # kept for scripts that read it; the next axis after x, y, z, x


def _parse_axes(axes: Any, what: str) -> tuple[bool, tuple[int, int, int]]:
    """(rotating?, (first, second, third) axis indices) for an axes string or 4-tuple."""
    name = axes.lower() if isinstance(axes, str) else _TUPLE2AXES.get(_as_code(axes))
    if name not in _AXES2TUPLE:
        raise ValueError(
            f"{what}: axes must be one of the 24 conventions such as 'sxyz' (static x, y, z; "
            f"the default) or 'rzyx' (rotating z, y, x), or their 4-tuples; got {axes!r}"
        )
    return name[0] == "r", tuple(_AXIS_INDEX[letter] for letter in name[1:])  # type: ignore[return-value]


def _as_code(axes: Any) -> Any:
    try:
        return tuple(int(value) for value in axes)
    except (TypeError, ValueError):
        return None


def _axis_matrix(axis: int, angle: float) -> np.ndarray:
    """3x3 rotation by `angle` [rad] about coordinate axis `axis` (0 x, 1 y, 2 z)."""
    cos, sin = math.cos(angle), math.sin(angle)
    after, other = (axis + 1) % 3, (axis + 2) % 3
    matrix = np.identity(3)
    matrix[after, after] = matrix[other, other] = cos
    matrix[other, after] = sin
    matrix[after, other] = -sin
    return matrix


def _axis_quaternion(axis: int, angle: float) -> np.ndarray:
    quaternion = np.zeros(4)
    quaternion[axis] = math.sin(angle / 2.0)
    quaternion[3] = math.cos(angle / 2.0)
    return quaternion


def _ordered(rotating: bool, axes: tuple[int, ...], angles: tuple[float, ...]) -> list[Any]:
    """(axis, angle) pairs from left to right in the product that builds the rotation."""
    pairs = list(zip(axes, angles, strict=True))
    return pairs if rotating else pairs[::-1]


def euler_matrix(ai: float, aj: float, ak: float, axes: Any = "sxyz") -> np.ndarray:
    """4x4 rotation from Euler angles [rad] in convention `axes`."""
    rotating, order = _parse_axes(axes, "euler_matrix()")
    rotation = np.identity(3)
    for axis, angle in _ordered(rotating, order, (float(ai), float(aj), float(ak))):
        rotation = rotation @ _axis_matrix(axis, angle)
    matrix = np.identity(4)
    matrix[:3, :3] = rotation
    return matrix


def quaternion_from_euler(ai: float, aj: float, ak: float, axes: Any = "sxyz") -> np.ndarray:
    """Quaternion [x, y, z, w] from Euler angles [rad] in convention `axes`."""
    rotating, order = _parse_axes(axes, "quaternion_from_euler()")
    quaternion = np.array([0.0, 0.0, 0.0, 1.0])
    for axis, angle in _ordered(rotating, order, (float(ai), float(aj), float(ak))):
        quaternion = quaternion_multiply(quaternion, _axis_quaternion(axis, angle))
    return quaternion


def _static_angles(m: np.ndarray, first: int, second: int, third: int) -> tuple[float, ...]:
    """Angles (a, b, c) with m = R_third(c) R_second(b) R_first(a), Shoemake's ranges."""
    sign = 1.0 if (second - first) % 3 == 1 else -1.0  # +1 when (first, second) is cyclic
    if first != third:  # Tait-Bryan: three different axes
        cos_b = math.hypot(m[first, first], m[second, first])
        b = math.atan2(-sign * m[third, first], cos_b)
        if cos_b > EPS:
            a = math.atan2(sign * m[third, second], m[third, third])
            c = math.atan2(sign * m[second, first], m[first, first])
        else:  # gimbal lock: only a + c (or a - c) is defined; put it all in a
            a, c = math.atan2(-sign * m[second, third], m[second, second]), 0.0
        return a, b, c
    other = 3 - first - second  # proper Euler: first axis repeated
    sin_b = math.hypot(m[first, second], m[first, other])
    # The middle angle is in [0, pi] for a cyclic pair of axes and in [-pi, 0] otherwise, as
    # in the module ROS ships (scipy uses [0, pi] for both: the same rotation).
    b = sign * math.atan2(sin_b, m[first, first])
    if sin_b > EPS:
        a = math.atan2(sign * m[first, second], m[first, other])
        c = math.atan2(sign * m[second, first], -m[other, first])
    else:
        a, c = math.atan2(-sign * m[second, other], m[second, second]), 0.0
    return a, b, c


def euler_from_matrix(matrix: Any, axes: Any = "sxyz") -> tuple[float, float, float]:
    """Euler angles (ai, aj, ak) [rad] of a rotation matrix in convention `axes`."""
    rotating, (first, second, third) = _parse_axes(axes, "euler_from_matrix()")
    rotation = as_matrix(matrix, "euler_from_matrix()")[:3, :3]
    if rotating:  # R_first(a) R_second(b) R_third(c) is the static sequence read backwards
        c, b, a = _static_angles(rotation, third, second, first)
        return a, b, c
    a, b, c = _static_angles(rotation, first, second, third)
    return a, b, c


def euler_from_quaternion(quaternion: Any, axes: Any = "sxyz") -> tuple[float, float, float]:
    """Euler angles (ai, aj, ak) [rad] of quaternion [x, y, z, w]; with the default 'sxyz' these
    are (roll, pitch, yaw)."""
    as_vector(quaternion, 4, "euler_from_quaternion()")
    return euler_from_matrix(quaternion_matrix(quaternion), axes)


def quaternion_about_axis(angle: float, axis: Any) -> np.ndarray:
    """Quaternion [x, y, z, w] of a rotation by `angle` [rad] about `axis`."""
    direction = as_vector(axis, 3, "quaternion_about_axis()")
    length = math.sqrt(float(direction @ direction))
    quaternion = np.zeros(4)
    if length > EPS:
        quaternion[:3] = direction * (math.sin(angle / 2.0) / length)
    quaternion[3] = math.cos(angle / 2.0)
    return quaternion


def quaternion_matrix(quaternion: Any) -> np.ndarray:
    """4x4 rotation of quaternion [x, y, z, w] (normalized first; ~zero gives the identity)."""
    q = as_vector(quaternion, 4, "quaternion_matrix()")
    norm2 = float(q @ q)
    if norm2 < EPS:
        return np.identity(4)
    x, y, z, w = q / math.sqrt(norm2)
    matrix = np.identity(4)
    matrix[:3, :3] = [
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ]
    return matrix


def quaternion_from_matrix(matrix: Any) -> np.ndarray:
    """Quaternion [x, y, z, w] of a rotation matrix (4x4, or 3x3). Sign: w >= 0 when the trace
    is positive, else the component of the largest diagonal element is positive (Shepperd)."""
    m = as_matrix(matrix, "quaternion_from_matrix()")
    scale = m[3, 3]
    trace = float(np.trace(m[:3, :3]))
    q = np.empty(4)
    if trace > 0.0:
        t = trace + scale
        q[3] = t
        q[0], q[1], q[2] = m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]
    else:
        i = int(np.argmax([m[0, 0], m[1, 1], m[2, 2]]))
        j, k = (i + 1) % 3, (i + 2) % 3
        t = m[i, i] - m[j, j] - m[k, k] + scale
        q[i] = t
        q[j] = m[i, j] + m[j, i]
        q[k] = m[k, i] + m[i, k]
        q[3] = m[k, j] - m[j, k]
    return q * (0.5 / math.sqrt(t * scale))


def quaternion_multiply(quaternion1: Any, quaternion0: Any) -> np.ndarray:
    """The Hamilton product quaternion1 * quaternion0 ([x, y, z, w]): rotate by quaternion0,
    then by quaternion1."""
    x1, y1, z1, w1 = as_vector(quaternion1, 4, "quaternion_multiply()")
    x0, y0, z0, w0 = as_vector(quaternion0, 4, "quaternion_multiply()")
    return np.array(
        [
            w1 * x0 + x1 * w0 + y1 * z0 - z1 * y0,
            w1 * y0 - x1 * z0 + y1 * w0 + z1 * x0,
            w1 * z0 + x1 * y0 - y1 * x0 + z1 * w0,
            w1 * w0 - x1 * x0 - y1 * y0 - z1 * z0,
        ]
    )


def quaternion_conjugate(quaternion: Any) -> np.ndarray:
    """[-x, -y, -z, w]."""
    q = as_vector(quaternion, 4, "quaternion_conjugate()")
    q[:3] = -q[:3]
    return q


def quaternion_inverse(quaternion: Any) -> np.ndarray:
    """The conjugate divided by the squared norm."""
    q = as_vector(quaternion, 4, "quaternion_inverse()")
    return quaternion_conjugate(q) / float(q @ q)


def quaternion_slerp(
    quat0: Any, quat1: Any, fraction: float, spin: int = 0, shortestpath: bool = True
) -> np.ndarray:
    """Spherical linear interpolation from quat0 (fraction 0) to quat1 (fraction 1); `spin`
    adds half turns, `shortestpath` flips quat1 when that is the shorter way round."""
    q0 = unit_vector(as_vector(quat0, 4, "quaternion_slerp()"))
    q1 = unit_vector(as_vector(quat1, 4, "quaternion_slerp()"))
    if fraction == 0.0:
        return q0
    if fraction == 1.0:
        return q1
    cos_angle = float(q0 @ q1)
    if abs(abs(cos_angle) - 1.0) < EPS:
        return q0
    if shortestpath and cos_angle < 0.0:
        cos_angle, q1 = -cos_angle, -q1
    angle = math.acos(max(-1.0, min(1.0, cos_angle))) + spin * math.pi
    if abs(angle) < EPS:
        return q0
    return (math.sin((1.0 - fraction) * angle) * q0 + math.sin(fraction * angle) * q1) / math.sin(
        angle
    )


def random_quaternion(rand: Any = None) -> np.ndarray:
    """A uniformly distributed unit quaternion; `rand` gives the three uniform [0, 1) numbers."""
    if rand is None:
        rand = np.random.rand(3)
    u = as_vector(rand, 3, "random_quaternion()")
    if len(np.asarray(rand).reshape(-1)) != 3:
        raise ValueError(f"random_quaternion() takes three numbers in [0, 1), got {rand!r}")
    low, high = math.sqrt(1.0 - u[0]), math.sqrt(u[0])
    theta1, theta2 = 2.0 * math.pi * u[1], 2.0 * math.pi * u[2]
    return np.array(
        [math.sin(theta1) * low, math.cos(theta1) * low, math.sin(theta2) * high,
         math.cos(theta2) * high]
    )  # fmt: skip


def random_rotation_matrix(rand: Any = None) -> np.ndarray:
    """A uniformly distributed 4x4 rotation."""
    return quaternion_matrix(random_quaternion(rand))


def rotation_matrix(angle: float, direction: Any, point: Any = None) -> np.ndarray:
    """4x4 rotation by `angle` [rad] about the axis along `direction` through `point`
    (the origin by default): Rodrigues' formula."""
    axis = unit_vector(as_vector(direction, 3, "rotation_matrix()"))
    cos, sin = math.cos(angle), math.sin(angle)
    cross = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    rotation = cos * np.identity(3) + sin * cross + (1.0 - cos) * np.outer(axis, axis)
    matrix = np.identity(4)
    matrix[:3, :3] = rotation
    if point is not None:
        centre = as_vector(point, 3, "rotation_matrix()")
        matrix[:3, 3] = centre - rotation @ centre
    return matrix


def _eigenvector(matrix: np.ndarray, value: float, what: str) -> np.ndarray:
    """A real eigenvector of `matrix` for eigenvalue `value` (the last one found)."""
    values, vectors = np.linalg.eig(matrix)
    found = np.where(abs(np.real(values) - value) < 1e-8)[0]
    if not len(found):
        raise ValueError(f"{what}: the matrix has no eigenvector with eigenvalue {value:g}")
    return np.real(vectors[:, found[-1]]).copy()


def rotation_from_matrix(matrix: Any) -> tuple[float, np.ndarray, np.ndarray]:
    """(angle [rad], axis direction, a point on the axis) of a 4x4 rotation."""
    m = np.asarray(matrix, dtype=np.float64)
    rotation = m[:3, :3]
    axis = _eigenvector(rotation, 1.0, "rotation_from_matrix()")
    point = _eigenvector(m, 1.0, "rotation_from_matrix()")
    point /= point[3]
    skew = np.array(
        [rotation[2, 1] - rotation[1, 2], rotation[0, 2] - rotation[2, 0],
         rotation[1, 0] - rotation[0, 1]]
    )  # fmt: skip
    cos = (float(np.trace(rotation)) - 1.0) / 2.0
    sin = float(skew @ axis) / 2.0
    return math.atan2(sin, cos), axis, point
