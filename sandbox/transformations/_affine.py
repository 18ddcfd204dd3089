"""The affine and projective 4x4 transforms of tf.transformations: reflection, scaling, shear,
projection, clipping, their inverses ("..._from_matrix"), decomposition and superimposition.

Sources: R. Goldman, "Matrices and transformations", Graphics Gems I (1990) pp. 472-475 and
"More matrices and transformations: shear and pseudo-perspective", Graphics Gems II (1991)
pp. 320-323; S. W. Thomas, "Decomposing a matrix into simple transformations", Graphics Gems II
(1991) pp. 320-323 (decompose_matrix: M = perspective . translate . rotate . shear . scale);
W. Kabsch, Acta Cryst. A34 (1978) 827-828 and B. K. P. Horn, J. Opt. Soc. Am. A 4(4) (1987)
629-642 (superimposition_matrix); the OpenGL glOrtho/glFrustum matrices (clip_matrix).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ._rotations import _eigenvector, euler_from_matrix, euler_matrix, quaternion_matrix
from ._vectors import EPS, as_vector, unit_vector


def _fixed_point(matrix: np.ndarray, what: str) -> np.ndarray:
    point = _eigenvector(matrix, 1.0, what)
    return point / point[3]


def reflection_matrix(point: Any, normal: Any) -> np.ndarray:
    """Mirror at the plane through `point` with `normal`."""
    n = unit_vector(as_vector(normal, 3, "reflection_matrix()"))
    p = as_vector(point, 3, "reflection_matrix()")
    matrix = np.identity(4)
    matrix[:3, :3] -= 2.0 * np.outer(n, n)
    matrix[:3, 3] = 2.0 * float(p @ n) * n
    return matrix


def reflection_from_matrix(matrix: Any) -> tuple[np.ndarray, np.ndarray]:
    """(point, normal) of the mirror plane of a reflection matrix."""
    m = np.asarray(matrix, dtype=np.float64)
    normal = _eigenvector(m[:3, :3], -1.0, "reflection_from_matrix()")
    return _fixed_point(m, "reflection_from_matrix()"), normal


def scale_matrix(factor: float, origin: Any = None, direction: Any = None) -> np.ndarray:
    """Scale by `factor` about `origin`, uniformly or only along `direction` (-1: mirror)."""
    matrix = np.identity(4)
    if direction is None:
        matrix[:3, :3] *= factor
        if origin is not None:
            matrix[:3, 3] = as_vector(origin, 3, "scale_matrix()") * (1.0 - factor)
        return matrix
    d = unit_vector(as_vector(direction, 3, "scale_matrix()"))
    matrix[:3, :3] -= (1.0 - factor) * np.outer(d, d)
    if origin is not None:
        o = as_vector(origin, 3, "scale_matrix()")
        matrix[:3, 3] = (1.0 - factor) * float(o @ d) * d
    return matrix


def scale_from_matrix(matrix: Any) -> tuple[float, np.ndarray, np.ndarray | None]:
    """(factor, origin, direction) of a scaling matrix; direction None for uniform scaling."""
    m = np.asarray(matrix, dtype=np.float64)
    linear = m[:3, :3]
    # Scaling along one direction leaves two eigenvalues 1, so the trace is factor + 2.
    factor = float(np.trace(linear)) - 2.0
    values, vectors = np.linalg.eig(linear)
    found = np.where(abs(np.real(values) - factor) < 1e-8)[0]
    if len(found):
        direction = np.real(vectors[:, found[0]])
        direction = direction / math.sqrt(float(direction @ direction))
    else:
        factor, direction = (factor + 2.0) / 3.0, None
    return factor, _fixed_point(m, "scale_from_matrix()"), direction


def projection_matrix(
    point: Any, normal: Any, direction: Any = None, perspective: Any = None, pseudo: bool = False
) -> np.ndarray:
    """Project onto the plane through `point` with `normal`: orthogonally, along `direction`,
    or from the eye point `perspective` (`pseudo` keeps relative depth, so that
    perspective = orthogonal . pseudo-perspective)."""
    p = as_vector(point, 3, "projection_matrix()")
    n = unit_vector(as_vector(normal, 3, "projection_matrix()"))
    matrix = np.identity(4)
    if perspective is not None:
        eye = as_vector(perspective, 3, "projection_matrix()")
        # x -> eye + (x - eye) * ((p - eye).n) / ((x - eye).n), in homogeneous form.
        matrix[:3, :3] = float((eye - p) @ n) * np.identity(3) - np.outer(eye, n)
        if pseudo:
            matrix[:3, :3] -= np.outer(n, n)
            matrix[:3, 3] = float(p @ n) * (eye + n)
        else:
            matrix[:3, 3] = float(p @ n) * eye
        matrix[3, :3] = -n
        matrix[3, 3] = float(eye @ n)
    elif direction is not None:
        d = as_vector(direction, 3, "projection_matrix()")
        along = float(d @ n)
        matrix[:3, :3] -= np.outer(d, n) / along
        matrix[:3, 3] = d * (float(p @ n) / along)
    else:
        matrix[:3, :3] -= np.outer(n, n)
        matrix[:3, 3] = float(p @ n) * n
    return matrix


def projection_from_matrix(matrix: Any, pseudo: bool = False) -> tuple[Any, ...]:
    """(point, normal, direction, perspective, pseudo): arguments that rebuild the projection."""
    m = np.asarray(matrix, dtype=np.float64)
    linear = m[:3, :3]
    values, vectors = np.linalg.eig(m)
    unit = np.where(abs(np.real(values) - 1.0) < 1e-8)[0]
    if not pseudo and len(unit):  # parallel or orthogonal: the plane's points are fixed
        point = np.real(vectors[:, unit[-1]])
        point = point / point[3]
        direction = unit_vector(_eigenvector(linear, 0.0, "projection_from_matrix()"))
        try:
            normal = unit_vector(_eigenvector(linear.T, 0.0, "projection_from_matrix()"))
        except ValueError:
            return point, direction, None, None, False
        return point, normal, direction, None, False
    # Perspective: plane points share the one non-zero eigenvalue; the eye maps to zero.
    nonzero = np.where(abs(np.real(values)) > 1e-8)[0]
    if not len(nonzero):
        raise ValueError("projection_from_matrix(): the matrix projects everything to a point")
    point = np.real(vectors[:, nonzero[-1]])
    point = point / point[3]
    normal = -m[3, :3]
    eye = m[:3, 3] / float(point[:3] @ normal)
    if pseudo:
        eye = eye - normal
    return point, normal, None, eye, pseudo


def clip_matrix(
    left: float,
    right: float,
    bottom: float,
    top: float,
    near: float,
    far: float,
    perspective: bool = False,
) -> np.ndarray:
    """Map the box (or, with `perspective`, the frustum from the origin along z) with these
    bounds to normalized device coordinates [-1, 1]^3 (divide by w after a perspective one)."""
    if left >= right or bottom >= top or near >= far:
        raise ValueError(
            "clip_matrix(): needs left < right, bottom < top and near < far, got "
            f"{(left, right, bottom, top, near, far)}"
        )
    width, height, depth = right - left, top - bottom, far - near
    if perspective:
        if near <= EPS:
            raise ValueError(f"clip_matrix(): a perspective frustum needs near > 0, got {near}")
        return np.array(
            [
                [-2.0 * near / width, 0.0, (right + left) / width, 0.0],
                [0.0, -2.0 * near / height, (top + bottom) / height, 0.0],
                [0.0, 0.0, -(far + near) / depth, 2.0 * near * far / depth],
                [0.0, 0.0, -1.0, 0.0],
            ]
        )
    return np.array(
        [
            [2.0 / width, 0.0, 0.0, -(right + left) / width],
            [0.0, 2.0 / height, 0.0, -(top + bottom) / height],
            [0.0, 0.0, 2.0 / depth, -(far + near) / depth],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def shear_matrix(angle: float, direction: Any, point: Any, normal: Any) -> np.ndarray:
    """Shear by `angle` [rad] along `direction` (which must be orthogonal to `normal`) relative
    to the plane through `point` with `normal`: x -> x + tan(angle) ((x - point).normal) dir."""
    n = unit_vector(as_vector(normal, 3, "shear_matrix()"))
    d = unit_vector(as_vector(direction, 3, "shear_matrix()"))
    if abs(float(n @ d)) > 1e-6:
        raise ValueError("shear_matrix(): direction and normal must be orthogonal")
    slope = math.tan(angle)
    matrix = np.identity(4)
    matrix[:3, :3] += slope * np.outer(d, n)
    matrix[:3, 3] = -slope * float(as_vector(point, 3, "shear_matrix()") @ n) * d
    return matrix


def shear_from_matrix(matrix: Any) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """(angle, direction, point, normal) of a shear matrix."""
    m = np.asarray(matrix, dtype=np.float64)
    # The linear part minus the identity is tan(angle) * direction normal^T: rank one.
    left, singular, right = np.linalg.svd(m[:3, :3] - np.identity(3))
    if singular[0] < EPS or singular[1] > 1e-6:
        raise ValueError("shear_from_matrix(): the matrix is not a shear")
    direction, normal = left[:, 0], right[0]
    slope = float(singular[0])
    offset = -float(m[:3, 3] @ direction) / slope  # the plane's distance from the origin
    point = np.append(offset * normal, 1.0)
    return math.atan(slope), direction, point, normal


def decompose_matrix(matrix: Any) -> tuple[Any, ...]:
    """(scale, shear, angles, translate, perspective) with
    M = perspective . translate . rotate('sxyz' angles) . shear(xy, xz, yz) . scale."""
    m = np.array(matrix, dtype=np.float64)
    if abs(m[3, 3]) < EPS:
        raise ValueError("decompose_matrix(): M[3, 3] is zero")
    m /= m[3, 3]
    affine = m.copy()
    affine[3] = (0.0, 0.0, 0.0, 1.0)
    if not np.linalg.det(affine):
        raise ValueError("decompose_matrix(): the matrix is singular")
    if np.any(abs(m[3, :3]) > EPS):
        perspective = m[3] @ np.linalg.inv(affine)
    else:
        perspective = np.array([0.0, 0.0, 0.0, 1.0])
    translate = affine[:3, 3].copy()
    columns = affine[:3, :3].copy()
    # Gram-Schmidt on the columns: linear = rotation . upper-triangular(shear . scale).
    scale = np.zeros(3)
    scale[0] = math.sqrt(float(columns[:, 0] @ columns[:, 0]))
    axis_x = columns[:, 0] / scale[0]
    xy = float(axis_x @ columns[:, 1])
    rest_y = columns[:, 1] - xy * axis_x
    scale[1] = math.sqrt(float(rest_y @ rest_y))
    axis_y = rest_y / scale[1]
    xz, yz = float(axis_x @ columns[:, 2]), float(axis_y @ columns[:, 2])
    rest_z = columns[:, 2] - xz * axis_x - yz * axis_y
    scale[2] = math.sqrt(float(rest_z @ rest_z))
    axis_z = rest_z / scale[2]
    shear = [xy / scale[1], xz / scale[2], yz / scale[2]]
    rotation = np.column_stack([axis_x, axis_y, axis_z])
    if np.linalg.det(rotation) < 0:  # a reflection: put the sign in the scale
        scale, rotation = -scale, -rotation
    angles = list(euler_from_matrix(rotation, "sxyz"))
    return scale, shear, angles, translate, perspective


def compose_matrix(
    scale: Any = None,
    shear: Any = None,
    angles: Any = None,
    translate: Any = None,
    perspective: Any = None,
) -> np.ndarray:
    """The inverse of decompose_matrix (any part may be left out)."""
    matrix = np.identity(4)
    if perspective is not None:
        part = np.identity(4)
        part[3] = as_vector(perspective, 4, "compose_matrix()")
        matrix = matrix @ part
    if translate is not None:
        part = np.identity(4)
        part[:3, 3] = as_vector(translate, 3, "compose_matrix()")
        matrix = matrix @ part
    if angles is not None:
        ai, aj, ak = as_vector(angles, 3, "compose_matrix()")
        matrix = matrix @ euler_matrix(ai, aj, ak, "sxyz")
    if shear is not None:
        xy, xz, yz = as_vector(shear, 3, "compose_matrix()")
        part = np.identity(4)
        part[0, 1], part[0, 2], part[1, 2] = xy, xz, yz
        matrix = matrix @ part
    if scale is not None:
        part = np.identity(4)
        part[[0, 1, 2], [0, 1, 2]] = as_vector(scale, 3, "compose_matrix()")
        matrix = matrix @ part
    return matrix / matrix[3, 3]


def orthogonalization_matrix(lengths: Any, angles: Any) -> np.ndarray:
    """Crystallographic cell (a, b, c lengths; alpha, beta, gamma in degrees) to Cartesian."""
    a, b, c = as_vector(lengths, 3, "orthogonalization_matrix()")
    alpha, beta, gamma = np.radians(as_vector(angles, 3, "orthogonalization_matrix()"))
    cos_gamma_star = (math.cos(alpha) * math.cos(beta) - math.cos(gamma)) / (
        math.sin(alpha) * math.sin(beta)
    )
    return np.array(
        [
            [a * math.sin(beta) * math.sqrt(1.0 - cos_gamma_star**2), 0.0, 0.0, 0.0],
            [-a * math.sin(beta) * cos_gamma_star, b * math.sin(alpha), 0.0, 0.0],
            [a * math.cos(beta), b * math.cos(alpha), c, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def superimposition_matrix(
    v0: Any, v1: Any, scaling: bool = False, usesvd: bool = True
) -> np.ndarray:
    """The rigid transform (with uniform scale if `scaling`) that best maps the point set v0
    onto v1 (shape (3, N) or (4, N), N >= 3) in the least-squares sense: Kabsch's SVD method,
    or Horn's quaternion method with usesvd=False."""
    src = np.array(v0, dtype=np.float64)[:3]
    dst = np.array(v1, dtype=np.float64)[:3]
    if src.shape != dst.shape or src.ndim != 2 or src.shape[1] < 3:
        raise ValueError(
            "superimposition_matrix(): give two point sets of the same shape (3, N), N >= 3"
        )
    src_centre, dst_centre = src.mean(axis=1), dst.mean(axis=1)
    src, dst = src - src_centre[:, None], dst - dst_centre[:, None]
    matrix = np.identity(4)
    if usesvd:
        left, _, right = np.linalg.svd(dst @ src.T)
        correction = np.diag([1.0, 1.0, np.sign(np.linalg.det(left @ right)) or 1.0])
        matrix[:3, :3] = left @ correction @ right
    else:
        s = src @ dst.T  # s[i, j] = sum over points of src_i * dst_j
        (sxx, sxy, sxz), (syx, syy, syz), (szx, szy, szz) = s
        horn = np.array(
            [
                [sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
                [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
                [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
                [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz],
            ]
        )
        values, vectors = np.linalg.eigh(horn)
        w, x, y, z = vectors[:, int(np.argmax(values))]
        matrix = quaternion_matrix([x, y, z, w])
    if scaling:
        matrix[:3, :3] *= math.sqrt(float(np.sum(dst * dst)) / float(np.sum(src * src)))
    matrix[:3, 3] = dst_centre - matrix[:3, :3] @ src_centre
    return matrix
