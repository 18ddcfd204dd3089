"""Random ROS 2 messages of any type, and their rosbags twins, for byte-for-byte comparisons."""

from __future__ import annotations

import random
from array import array
from typing import Any

import numpy

from sandbox.msgs2._spec import INT_RANGES, PRIMITIVES, FieldSpec

_TEXTS = ["", "a", "base_link", "héllo wörld", "日本語のテキスト", "emoji 🤖", "x" * 37]


def _value(field: FieldSpec, rng: random.Random, depth: int) -> Any:
    if field.message_class is not None:
        return random_message(field.message_class, rng, depth + 1)
    primitive = PRIMITIVES[field.base]
    if field.base == "string":
        text = rng.choice(_TEXTS)
        return text[: field.string_bound] if field.string_bound is not None else text
    if primitive.python == "bool":
        return rng.random() < 0.5
    if primitive.python == "bytes":
        return bytes([rng.randrange(256)])
    if primitive.python == "int":
        low, high = INT_RANGES[primitive.code]
        return rng.choice([low, high, 0, rng.randint(low, high)])
    value = rng.choice(
        [0.0, -1.5, 1e300 if primitive.code == "d" else 1e30, rng.uniform(-1e3, 1e3)]
    )
    return float(numpy.float32(value)) if primitive.code == "f" else value


def _count(field: FieldSpec, rng: random.Random, depth: int) -> int:
    if field.container == "array":
        return field.size or 0
    high = 0 if depth > 3 else 5
    if field.size is not None:
        high = min(high, field.size)
    return rng.choice([0, rng.randint(0, high)])


def random_message(cls: type, rng: random.Random, depth: int = 0) -> Any:
    """A message of ``cls`` with every field set to a random legal value."""
    values = {}
    for field in cls._field_specs:
        if field.container is None:
            values[field.name] = _value(field, rng, depth)
        else:
            items = [_value(field, rng, depth) for _ in range(_count(field, rng, depth))]
            values[field.name] = items
    return cls(**values)


def to_rosbags(message: Any, typestore: Any) -> Any:
    """The rosbags dataclass instance holding the same values as ``message``."""
    rosbags_cls = typestore.types[message._type]
    if not message._field_specs:
        return rosbags_cls(structure_needs_at_least_one_member=0)
    values = {}
    for field in message._field_specs:
        value = getattr(message, field.name)
        primitive = field.primitive
        if field.message_class is not None:
            if field.container is None:
                values[field.name] = to_rosbags(value, typestore)
            else:
                values[field.name] = [to_rosbags(item, typestore) for item in value]
        elif field.container is None:
            # rosbags packs a byte scalar as a signed int8; the bits are the same.
            values[field.name] = (
                value[0] - 256 * (value[0] > 127) if primitive.python == "bytes" else value
            )
        elif field.base == "string":
            values[field.name] = list(value)
        elif primitive.python == "bytes":
            values[field.name] = numpy.array([item[0] for item in value], dtype=numpy.uint8)
        elif primitive.python == "bool":
            values[field.name] = numpy.array(value, dtype=numpy.bool_)
        else:
            values[field.name] = numpy.array(
                value.tolist() if isinstance(value, array) else value,
                dtype=numpy.dtype("<" + primitive.typecode),
            )
    return rosbags_cls(**values)


def _rosbags_node(field: FieldSpec) -> tuple:
    from rosbags.interfaces import Nodetype

    if field.message_class is not None:
        element: tuple = (Nodetype.NAME, field.base)
    else:
        element = (Nodetype.BASE, (field.base, field.string_bound or 0))
    if field.container == "array":
        return (Nodetype.ARRAY, (element, field.size))
    if field.container == "sequence":
        return (Nodetype.SEQUENCE, (element, field.size or 0))
    return element


def typestore_with(types: list[type]) -> Any:
    """rosbags' Jazzy type store plus ``types`` (and what they nest), from our parsed fields."""
    from rosbags.typesys import Stores, get_typestore

    typestore = get_typestore(Stores.ROS2_JAZZY)
    todo, definitions = list(types), {}
    while todo:
        cls = todo.pop()
        if cls._type in typestore.types or cls._type in definitions:
            continue
        fields = [(f.name, _rosbags_node(f)) for f in cls._field_specs]
        if not fields:
            fields = [("structure_needs_at_least_one_member", _rosbags_node(
                FieldSpec("x", "uint8", "uint8", None, None)))]  # fmt: skip
        definitions[cls._type] = ([], fields)
        todo += [f.message_class for f in cls._field_specs if f.message_class is not None]
    typestore.register(definitions)
    return typestore
