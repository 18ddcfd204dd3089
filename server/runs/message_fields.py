"""The fields of a message class, ROS 1 (sandbox.msgs) or ROS 2 (sandbox.msgs2), in one shape
for the readers that walk them (CSV export, the browser's JSON).

The two packages parse definitions into field specs of their own (ROS 1's knows `time` and
`duration` primitives; ROS 2's has containers, bounds and `builtin_interfaces/Time` messages).
A reader needs less: the field's name, what kind of value it holds, whether it is an array, the
struct code of a number (float32 and float64 print differently) and the nested class. In ROS 2,
`byte` holds a one-byte `bytes` value (rosidl's octet), given here the kind "byte".
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

# rosidl_generator_py's Python type of a ROS 2 primitive -> the kind readers know
_ROS2_KINDS = {"int": "int", "float": "float", "bool": "bool", "str": "string", "bytes": "byte"}


@dataclass(frozen=True, slots=True)
class FieldShape:
    name: str
    kind: str  # "int", "float", "bool", "string", "byte", "time", "duration" or "message"
    is_array: bool  # fixed array or sequence
    code: str  # struct code of one element: "f" float32, "d" float64; "" strings, messages
    message_class: Any = None  # the nested class of a "message" field


@functools.cache
def field_shapes(cls: type) -> tuple[FieldShape, ...]:
    """The fields of message class `cls` in definition order."""
    shapes = []
    for spec in cls._field_specs:  # type: ignore[attr-defined]
        if hasattr(spec, "is_array"):  # ROS 1 (sandbox.msgs._spec.FieldSpec)
            shapes.append(
                FieldShape(spec.name, spec.kind, spec.is_array, spec.code, spec.message_class)
            )
            continue
        primitive = spec.primitive  # ROS 2 (sandbox.msgs2._spec.FieldSpec)
        is_array = spec.container is not None
        if primitive is None:
            shapes.append(FieldShape(spec.name, "message", is_array, "", spec.message_class))
        else:
            kind = _ROS2_KINDS[primitive.python]
            shapes.append(FieldShape(spec.name, kind, is_array, primitive.code))
    return tuple(shapes)


def byte_value(value: Any) -> int:
    """A ROS 2 `byte` (b'\\x07') as its number."""
    if isinstance(value, bytes | bytearray):
        return value[0] if value else 0
    return int(value)
