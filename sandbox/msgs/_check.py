"""Explain why a message failed to serialize, naming the field: ``Twist.linear.x: expected ...``.

Only called after the fast generated serializer has already failed, so it can afford to walk
every field and check each value the slow way.
"""

from __future__ import annotations

import math
import numbers
from typing import Any

from ._spec import INT_RANGES, FieldSpec

_FLOAT32_MAX = 3.4028234663852886e38  # largest finite IEEE-754 single


def _describe(value: Any) -> str:
    text = repr(value)
    if len(text) > 60:
        text = text[:57] + "..."
    return f"{text} ({type(value).__name__})"


def _check_primitive(field: FieldSpec, value: Any, path: str) -> str | None:
    kind, code = field.kind, field.code
    if kind in ("int", "bool"):
        if not isinstance(value, numbers.Integral):
            wanted = "a bool" if kind == "bool" else "an int"
            return f"{path}: expected {wanted}, got {_describe(value)}"
        low, high = INT_RANGES[code]
        if not low <= int(value) <= high:
            return f"{path}: {int(value)} is out of range for {field.base_type} ({low}..{high})"
    elif kind == "float":
        if not isinstance(value, numbers.Real):
            return f"{path}: expected a float, got {_describe(value)}"
        number = float(value)
        if code == "f" and math.isfinite(number) and abs(number) > _FLOAT32_MAX:
            return f"{path}: {number} is too large for float32 (max {_FLOAT32_MAX:.7g})"
    elif kind == "string":
        if not isinstance(value, str | bytes | bytearray):
            return f"{path}: expected a str, got {_describe(value)}"
    elif kind in ("time", "duration"):
        secs, nsecs = getattr(value, "secs", None), getattr(value, "nsecs", None)
        if not isinstance(secs, numbers.Integral) or not isinstance(nsecs, numbers.Integral):
            wanted = "Time" if kind == "time" else "Duration"
            return f"{path}: expected a {wanted}, got {_describe(value)}"
        low, high = INT_RANGES["I" if kind == "time" else "i"]
        for part, number in (("secs", secs), ("nsecs", nsecs)):
            if not low <= number <= high:
                return f"{path}.{part}: {number} is out of range for {kind} ({low}..{high})"
    return None


def _check_value(field: FieldSpec, value: Any, path: str) -> str | None:
    cls = field.message_class
    if cls is None:
        return _check_primitive(field, value, path)
    if not isinstance(value, cls):
        return f"{path}: expected a {cls._type} message, got {_describe(value)}"
    return find_problem(cls, value, path)


def find_problem(cls: Any, message: Any, path: str) -> str | None:
    """First problem in ``message`` as a sentence starting with its field path, or None."""
    for field in cls._field_specs:
        field_path = f"{path}.{field.name}"
        try:
            value = getattr(message, field.name)
        except AttributeError:
            return f"{field_path}: field is not set"
        if not field.is_array:
            problem = _check_value(field, value, field_path)
        else:
            problem = _check_array(field, value, field_path)
        if problem:
            return problem
    return None


def _check_array(field: FieldSpec, value: Any, path: str) -> str | None:
    if isinstance(value, str) or not hasattr(value, "__len__") or not hasattr(value, "__iter__"):
        return f"{path}: expected a sequence of {field.base_type}, got {_describe(value)}"
    if field.array_len is not None and len(value) != field.array_len:
        return f"{path}: expected exactly {field.array_len} items, got {len(value)}"
    element = FieldSpec(
        field.name, field.base_type, field.base_type, False, None, field.message_class
    )
    for index, item in enumerate(value):
        problem = _check_value(element, item, f"{path}[{index}]")
        if problem:
            return problem
    return None


def explain_failure(cls: Any, message: Any, error: BaseException) -> str:
    """Sentence for a failed ``serialize()``: the field and value if found, else the error."""
    problem = find_problem(cls, message, cls._type)
    if problem:
        return problem
    return f"{cls._type}: could not serialize ({type(error).__name__}: {error})"
