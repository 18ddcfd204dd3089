"""Parse ROS1 ``.msg`` definition text and compute what genmsg derives from it.

This is the only place that understands the ``.msg`` grammar: primitive fields, fixed (``T[N]``)
and variable (``T[]``) arrays, nested message types, and constants (``uint8 INFRARED=1``). The
md5sum and the "full text" (a definition followed by the definitions it depends on) follow
genmsg's ``compute_md5_text`` and ``compute_full_text`` so that our sums and MCAP/rosserial schemas
match a real ROS1 installation byte for byte.
"""

from __future__ import annotations

import hashlib
import re
import struct
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

# Primitive name -> (struct code, kind). ``byte`` and ``char`` are ROS1's deprecated aliases of
# int8 and uint8; they keep their own name in the md5 text, so they are listed separately.
PRIMITIVES: dict[str, tuple[str, str]] = {
    "bool": ("B", "bool"),  # ROS1 sends bool as one uint8 byte
    "int8": ("b", "int"),
    "byte": ("b", "int"),
    "uint8": ("B", "int"),
    "char": ("B", "int"),
    "int16": ("h", "int"),
    "uint16": ("H", "int"),
    "int32": ("i", "int"),
    "uint32": ("I", "int"),
    "int64": ("q", "int"),
    "uint64": ("Q", "int"),
    "float32": ("f", "float"),
    "float64": ("d", "float"),
    "string": ("", "string"),
    "time": ("II", "time"),  # uint32 secs, uint32 nsecs
    "duration": ("ii", "duration"),  # int32 secs, int32 nsecs
}

# Inclusive value range of each integer struct code, used to explain out-of-range values.
INT_RANGES: dict[str, tuple[int, int]] = {
    code: (-(2 ** (8 * size - 1)), 2 ** (8 * size - 1) - 1)
    if code.islower()
    else (0, 2 ** (8 * size) - 1)
    for code, size in zip("bBhHiIqQ", (1, 1, 2, 2, 4, 4, 8, 8), strict=True)
}

_NAME_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_TYPE_RE = re.compile(r"^(?P<base>[A-Za-z][A-Za-z0-9_/]*)(?P<array>\[(?P<len>[0-9]*)\])?$")


@dataclass(frozen=True)
class FieldSpec:
    """One field of a message: ``float64[9] orientation_covariance``."""

    name: str
    written_type: str  # as in the definition, e.g. "float64[9]" or "Header"
    base_type: str  # resolved element type: "float64" or "std_msgs/Header"
    is_array: bool
    array_len: int | None  # None for variable-length arrays and scalars
    message_class: Any = None  # the nested Message subclass, None for primitives

    @property
    def kind(self) -> str:
        """ "int", "float", "bool", "string", "time", "duration" or "message"."""
        return "message" if self.message_class is not None else PRIMITIVES[self.base_type][1]

    @property
    def code(self) -> str:
        """struct code of one element ("" for strings and messages)."""
        return "" if self.message_class is not None else PRIMITIVES[self.base_type][0]

    @property
    def full_type(self) -> str:
        """Resolved type including the array suffix, as genpy's ``_slot_types`` lists it."""
        if not self.is_array:
            return self.base_type
        return f"{self.base_type}[{'' if self.array_len is None else self.array_len}]"


@dataclass(frozen=True)
class ConstantSpec:
    """A constant such as ``uint8 ULTRASOUND=0``; ``value_text`` is what the md5 hashes."""

    type: str
    name: str
    value: Any
    value_text: str


def resolve_type(package: str, type_name: str) -> str:
    """Resolve a written element type to a primitive name or a full "pkg/Name"."""
    if type_name in PRIMITIVES:
        return type_name
    if type_name == "Header":  # genmsg special-cases the bare name Header
        return "std_msgs/Header"
    if "/" in type_name:
        return type_name
    return f"{package}/{type_name}"


def _strip_comment(line: str) -> str:
    return line.split("#", 1)[0].strip()


def _parse_constant(msg_type: str, line: str) -> ConstantSpec:
    const_type = line.split(None, 1)[0]
    rest = line.split(None, 1)[1]
    if const_type == "string":
        # genmsg keeps everything after '=' for string constants, '#' included.
        name, _, value_text = rest.partition("=")
        name, value_text = name.strip(), value_text.strip()
        value: Any = value_text
    else:
        name, _, value_text = _strip_comment(rest).partition("=")
        name, value_text = name.strip(), value_text.strip()
        kind = PRIMITIVES.get(const_type, ("", ""))[1]
        if kind not in ("int", "float", "bool"):
            raise ValueError(f"{msg_type}: constant {name} has non-primitive type {const_type!r}")
        try:
            value = float(value_text) if kind == "float" else int(value_text)
        except ValueError:
            raise ValueError(
                f"{msg_type}: constant {name}={value_text!r} is not a valid {const_type}"
            ) from None
        if kind == "bool":
            value = bool(value)
    if not _NAME_RE.match(name):
        raise ValueError(f"{msg_type}: {name!r} is not a valid constant name")
    return ConstantSpec(const_type, name, value, value_text)


def parse_definition(
    msg_type: str, text: str, lookup: Callable[[str], Any]
) -> tuple[list[ConstantSpec], list[FieldSpec]]:
    """Parse ``.msg`` text; ``lookup("pkg/Name")`` returns the class of a nested type."""
    package = msg_type.split("/", 1)[0]
    constants: list[ConstantSpec] = []
    fields: list[FieldSpec] = []
    for raw_line in text.splitlines():
        line = _strip_comment(raw_line)
        if not line:
            continue
        if "=" in line:
            constants.append(_parse_constant(msg_type, raw_line.strip()))
            continue
        parts = line.split()
        if len(parts) != 2:
            raise ValueError(
                f"{msg_type}: cannot parse line {raw_line.strip()!r}; want 'type name'"
            )
        written_type, name = parts
        match = _TYPE_RE.match(written_type)
        if match is None or not _NAME_RE.match(name):
            raise ValueError(f"{msg_type}: invalid field {raw_line.strip()!r}")
        if name in {f.name for f in fields}:
            raise ValueError(f"{msg_type}: field {name!r} is declared twice")
        base = resolve_type(package, match["base"])
        message_class = None if base in PRIMITIVES else lookup(base)
        is_array = match["array"] is not None
        array_len = int(match["len"]) if is_array and match["len"] else None
        fields.append(FieldSpec(name, written_type, base, is_array, array_len, message_class))
    return constants, fields


def compute_md5_text(constants: Sequence[ConstantSpec], fields: Sequence[FieldSpec]) -> str:
    """The text genmsg hashes: constants first, nested types replaced by their md5."""
    lines = [f"{c.type} {c.name}={c.value_text}" for c in constants]
    for field in fields:
        if field.message_class is None:
            lines.append(f"{field.written_type} {field.name}")
        else:
            # An array of messages hashes as the bare nested md5, without "[]".
            lines.append(f"{field.message_class._md5sum} {field.name}")
    return "\n".join(lines).strip()


def compute_md5(constants: Sequence[ConstantSpec], fields: Sequence[FieldSpec]) -> str:
    """md5sum of a message as genmsg computes it (``gentools.compute_md5``)."""
    return hashlib.md5(compute_md5_text(constants, fields).encode()).hexdigest()


def compute_service_md5(request: Any, response: Any) -> str:
    """md5sum of a service: one hash over the request's then the response's md5 text."""
    digest = hashlib.md5()
    for cls in (request, response):
        digest.update(compute_md5_text(cls._constant_specs, cls._field_specs).encode())
    return digest.hexdigest()


def dependency_order(fields: list[FieldSpec]) -> list[Any]:
    """Nested message classes, depth first in field order, each once (as genmsg lists them)."""
    seen: list[Any] = []

    def visit(field_list: list[FieldSpec]) -> None:
        for field in field_list:
            cls = field.message_class
            if cls is not None and cls not in seen:
                seen.append(cls)
                visit(cls._field_specs)

    visit(fields)
    return seen


def compute_full_text(definition: str, fields: list[FieldSpec]) -> str:
    """The definition followed by each dependency, as in bag/MCAP ``message_definition``."""
    chunks = [definition + "\n"]
    for cls in dependency_order(fields):
        chunks.append("=" * 80 + "\n")
        chunks.append(f"MSG: {cls._type}\n{cls._definition}\n")
    return "".join(chunks)[:-1]


def min_wire_size(fields: list[FieldSpec]) -> int:
    """Smallest possible serialized size in bytes; bounds array counts read from the wire."""
    total = 0
    for field in fields:
        if field.message_class is not None:
            element = field.message_class._min_size
        elif field.kind == "string":
            element = 4
        else:
            element = struct.calcsize("<" + field.code)
        if field.is_array:
            total += 4 if field.array_len is None else element * field.array_len
        else:
            total += element
    return total
