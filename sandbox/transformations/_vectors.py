"""Vector norms and the plain 4x4 helpers of tf.transformations (identity, translation,
inverse, concatenation, comparison), plus the argument checks the other modules share.

Arguments are "array like" (tuple, list, numpy array); results are numpy float64 arrays, as in
the transformations module ROS ships (C. Gohlke's transformations.py, version 2009-04-18).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

# Below this, a length or determinant counts as zero: four float64 ulps, the tolerance the ROS
# module documents for its degenerate cases.
EPS = float(np.finfo(float).eps) * 4.0  # [1]


def as_vector(value: Any, size: int, what: str) -> np.ndarray:
    """`value` as a float64 vector of at least `size` numbers (extra ones are ignored, as a
    homogeneous point [x, y, z, 1] may stand for [x, y, z]); a sentence if it is not."""
    if hasattr(value, "_type") and hasattr(value, "x"):
        fields = "[q.x, q.y, q.z, q.w]" if hasattr(value, "w") else "[v.x, v.y, v.z]"
        raise TypeError(
            f"{what} takes a list of numbers, not a {value._type} message; for a message v "
            f"pass {fields}"
        )
    try:
        array = np.asarray(value, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError):
        raise TypeError(f"{what} takes a list of {size} numbers, got {value!r}") from None
    if array.size < size:
        raise ValueError(f"{what} takes a list of {size} numbers, got {array.size}: {value!r}")
    return array[:size].copy()


def as_matrix(value: Any, what: str) -> np.ndarray:
    """A 4x4 float64 copy of `value`; a 3x3 rotation is embedded in a homogeneous matrix."""
    try:
        matrix = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{what} takes a 4x4 matrix, got {value!r}") from None
    if matrix.shape == (3, 3):
        full = np.identity(4)
        full[:3, :3] = matrix
        return full
    if matrix.ndim != 2 or matrix.shape[0] < 4 or matrix.shape[1] < 4:
        raise ValueError(f"{what} takes a 4x4 (or 3x3) matrix, got shape {matrix.shape}")
    return matrix[:4, :4].copy()


def identity_matrix() -> np.ndarray:
    """The 4x4 identity transform."""
    return np.identity(4)


def translation_matrix(direction: Any) -> np.ndarray:
    """The 4x4 transform that moves points by `direction` [x, y, z]."""
    matrix = np.identity(4)
    matrix[:3, 3] = as_vector(direction, 3, "translation_matrix()")
    return matrix


def translation_from_matrix(matrix: Any) -> np.ndarray:
    """The translation [x, y, z] of a homogeneous transform."""
    return np.array(np.asarray(matrix, dtype=np.float64)[:3, 3])


def inverse_matrix(matrix: Any) -> np.ndarray:
    """The inverse of a square matrix."""
    return np.linalg.inv(np.asarray(matrix, dtype=np.float64))


def concatenate_matrices(*matrices: Any) -> np.ndarray:
    """The product of the matrices, left to right (the rightmost is applied first)."""
    result = np.identity(4)
    for matrix in matrices:
        result = result @ np.asarray(matrix, dtype=np.float64)
    return result


def is_same_transform(matrix0: Any, matrix1: Any) -> bool:
    """Whether two homogeneous matrices transform points alike (up to their overall scale)."""
    first = np.array(matrix0, dtype=np.float64)
    second = np.array(matrix1, dtype=np.float64)
    return bool(np.allclose(first / first[3, 3], second / second[3, 3]))


def vector_norm(data: Any, axis: int | None = None, out: np.ndarray | None = None) -> Any:
    """Euclidean length of `data` (a float for a vector), or of its slices along `axis`;
    with `out`, the lengths are written there and None is returned."""
    array = np.asarray(data, dtype=np.float64)
    if out is None and array.ndim == 1:
        return math.sqrt(float(np.dot(array, array)))
    lengths = np.sqrt(np.sum(array * array, axis=axis))
    if out is None:
        return np.atleast_1d(lengths)
    out[...] = lengths
    return None


def unit_vector(data: Any, axis: int | None = None, out: np.ndarray | None = None) -> Any:
    """`data` divided by its Euclidean length (along `axis`); with `out`, written there."""
    array = np.array(data, dtype=np.float64)
    if out is None and array.ndim == 1:
        return array / math.sqrt(float(np.dot(array, array)))
    lengths = np.sqrt(np.sum(array * array, axis=axis))
    if axis is not None:
        lengths = np.expand_dims(lengths, axis)
    result = array / lengths
    if out is None:
        return result
    out[...] = result
    return None


def random_vector(size: Any) -> np.ndarray:
    """Random doubles in [0, 1)."""
    return np.random.random(size)
