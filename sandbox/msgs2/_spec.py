"""Parse ROS 2 ``.msg`` definition text into field and constant specs.

The grammar is the one rosidl_adapter reads (ros2/rosidl, ``rosidl_adapter/parser.py``) and the
ROS 2 design article "Interface definitions" describes: primitive fields, fixed arrays
(``float64[9]``), unbounded (``float32[]``) and bounded (``int32[<=5]``) sequences, bounded
strings (``string<=10``), nested types (``Vector3`` in the same package or
``std_msgs/Header``), constants (``uint8 FOO=1``) and default values (``bool read_only false``).

What a type means to Python (``float64`` is rosidl's ``double``, kept in an ``array.array('d')``
inside a sequence and a ``numpy.float64`` array inside a fixed array) follows
rosidl_generator_py's ``generate_py_impl.py`` (``SPECIAL_NESTED_BASIC_TYPES``,
``get_python_type``).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from sandbox import python_ast


@dataclass(frozen=True)
class Primitive:
    """One ROS 2 primitive: its CDR encoding and its rosidl (IDL) spelling."""

    code: str  # struct code of one value ("" for strings)
    size: int  # bytes on the wire, also its CDR alignment (XCDR1: natural alignment)
    python: str  # the Python type rosidl_generator_py uses: "int", "float", "bool", ...
    idl: str  # rosidl_parser's typename: "double", "boolean", "octet", "uint8", ...
    typecode: str = ""  # array.array / numpy typecode for numeric sequences and arrays


# `char` is uint8 and `byte` is octet in ROS 2 (rosidl_adapter's MSG_TYPE_TO_IDL).
PRIMITIVES: dict[str, Primitive] = {
    "bool": Primitive("?", 1, "bool", "boolean"),
    "byte": Primitive("c", 1, "bytes", "octet"),
    "char": Primitive("B", 1, "int", "uint8", "B"),
    "int8": Primitive("b", 1, "int", "int8", "b"),
    "uint8": Primitive("B", 1, "int", "uint8", "B"),
    "int16": Primitive("h", 2, "int", "int16", "h"),
    "uint16": Primitive("H", 2, "int", "uint16", "H"),
    "int32": Primitive("i", 4, "int", "int32", "i"),
    "uint32": Primitive("I", 4, "int", "uint32", "I"),
    "int64": Primitive("q", 8, "int", "int64", "q"),
    "uint64": Primitive("Q", 8, "int", "uint64", "Q"),
    "float32": Primitive("f", 4, "float", "float", "f"),
    "float64": Primitive("d", 8, "float", "double", "d"),
    "string": Primitive("", 4, "str", "string"),  # uint32 length (incl. NUL), bytes, NUL
}

# numpy dtype names of rosidl's SPECIAL_NESTED_BASIC_TYPES, keyed by array typecode.
NUMPY_DTYPES = {
    "b": "int8",
    "B": "uint8",
    "h": "int16",
    "H": "uint16",
    "i": "int32",
    "I": "uint32",
    "q": "int64",
    "Q": "uint64",
    "f": "float32",
    "d": "float64",
}

# Inclusive range of each integer struct code, for the setters' range checks.
INT_RANGES: dict[str, tuple[int, int]] = {
    code: (-(2 ** (8 * size - 1)), 2 ** (8 * size - 1) - 1)
    if code.islower()
    else (0, 2 ** (8 * size) - 1)
    for code, size in zip("bBhHiIqQ", (1, 1, 2, 2, 4, 4, 8, 8), strict=True)
}
FLOAT_BOUNDS = {"f": 3.402823466e38, "d": 1.7976931348623157e308}  # rosidl's float/double range

# rosidl adds this uint8 member to a structure with no fields (rosidl_parser.definition's
# EMPTY_STRUCTURE_REQUIRED_MEMBER_NAME): one zero byte on the wire, no Python attribute.
EMPTY_FILLER = "structure_needs_at_least_one_member"

_NAME_RE = re.compile(r"^[a-z][a-z0-9_]*$", re.IGNORECASE)
_CONSTANT_RE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*\s*=")
_TYPE_RE = re.compile(
    r"^(?P<base>[A-Za-z][A-Za-z0-9_/]*)(?:<=(?P<strbound>[0-9]+))?"
    r"(?:\[(?P<bounded><=)?(?P<len>[0-9]*)\])?$"
)


@dataclass(frozen=True)
class FieldSpec:
    """One field: ``float64[9] orientation_covariance`` or ``int32[<=5] picks``."""

    name: str
    written_type: str  # as the definition writes it
    base: str  # primitive name or "pkg/msg/Name"
    container: str | None  # None, "array" (fixed size) or "sequence"
    size: int | None  # array size or sequence bound (None: unbounded)
    string_bound: int | None = None  # for string<=N
    default: Any = None  # Python value of the definition's default, None if none
    message_class: Any = None

    @property
    def primitive(self) -> Primitive | None:
        return PRIMITIVES.get(self.base)

    @property
    def is_numeric_container(self) -> bool:
        """Held in array.array (sequences) or numpy arrays (fixed arrays), as rosidl does."""
        primitive = self.primitive
        return self.container is not None and primitive is not None and bool(primitive.typecode)

    @property
    def idl_type(self) -> str:
        """The element's spelling in ``get_fields_and_field_types()``."""
        primitive = self.primitive
        if primitive is None:
            package, _, name = self.base.split("/")
            return f"{package}/{name}"
        if self.base == "string" and self.string_bound is not None:
            return f"string<{self.string_bound}>"
        return primitive.idl

    @property
    def field_type(self) -> str:
        """rosidl's ``_fields_and_field_types`` value: ``sequence<double>``, ``double[36]``."""
        element = self.idl_type
        if self.container == "array":
            return f"{element}[{self.size}]"
        if self.container == "sequence":
            bound = "" if self.size is None else f", {self.size}"
            return f"sequence<{element}{bound}>"
        return element


@dataclass(frozen=True)
class ConstantSpec:
    type: str
    name: str
    value: Any


def resolve_type(package: str, type_name: str) -> str:
    """A written element type as a primitive name or a full ``pkg/msg/Name``."""
    if type_name in PRIMITIVES:
        return type_name
    parts = type_name.split("/")
    if len(parts) == 1:
        return f"{package}/msg/{type_name}"
    if len(parts) == 2:
        return f"{parts[0]}/msg/{parts[1]}"
    return type_name


def _literal(msg_type: str, base: str, text: str, where: str) -> Any:
    """A constant's or default's value text as Python, as rosidl_adapter reads it."""
    primitive = PRIMITIVES.get(base)
    if primitive is None:
        raise ValueError(f"{msg_type}: {where} has non-primitive type {base!r}")
    if base == "string":
        text = text.strip()
        if len(text) >= 2 and text[0] == text[-1] and text[0] in "'\"":
            return python_ast.literal_eval(text)
        return text
    text = text.strip()
    if primitive.python == "bool":
        if text.lower() in ("true", "1"):
            return True
        if text.lower() in ("false", "0"):
            return False
        raise ValueError(f"{msg_type}: {where}: {text!r} is not a bool")
    try:
        if primitive.python == "bytes":  # octet constants are bytes([value]) in rosidl
            return bytes([int(text, 0)])
        return float(text) if primitive.python == "float" else int(text, 0)
    except ValueError:
        raise ValueError(f"{msg_type}: {where}: {text!r} is not a valid {base}") from None


def _default(msg_type: str, field: FieldSpec, text: str) -> Any:
    if field.container is None:
        return _literal(msg_type, field.base, text, f"default of {field.name}")
    items = python_ast.literal_eval(text.strip())
    return [
        _literal(msg_type, field.base, repr(item), f"default of {field.name}") for item in items
    ]


def _strip_comment(line: str) -> str:
    return line.split("#", 1)[0].strip()


def parse_definition(
    msg_type: str, text: str, lookup: Callable[[str], Any]
) -> tuple[list[ConstantSpec], list[FieldSpec]]:
    """Parse ``.msg`` text; ``lookup("pkg/msg/Name")`` returns the class of a nested type."""
    package = msg_type.split("/", 1)[0]
    constants: list[ConstantSpec] = []
    fields: list[FieldSpec] = []
    for raw_line in text.splitlines():
        line = raw_line.strip()
        if not _strip_comment(line):
            continue
        written_type, _, rest = line.partition(" ")
        rest = rest.strip()
        if _CONSTANT_RE.match(rest):
            name, _, value_text = rest.partition("=")
            if written_type != "string":
                value_text = _strip_comment(value_text)
            name = name.strip()
            value = _literal(msg_type, written_type, value_text, f"constant {name}")
            constants.append(ConstantSpec(written_type, name, value))
            continue
        name, _, default_text = rest.partition(" ")
        if written_type != "string":
            default_text = _strip_comment(default_text)
        match = _TYPE_RE.match(written_type)
        if match is None or not _NAME_RE.match(name):
            raise ValueError(f"{msg_type}: cannot parse line {raw_line.strip()!r}")
        if match["base"] == "wstring":
            raise ValueError(f"{msg_type}: wstring fields are not supported")
        if name in {f.name for f in fields}:
            raise ValueError(f"{msg_type}: field {name!r} is declared twice")
        base = resolve_type(package, match["base"])
        container = None
        size = None
        if match["len"] is not None or match["bounded"]:
            container = "sequence" if (match["bounded"] or not match["len"]) else "array"
            size = int(match["len"]) if match["len"] else None
        field = FieldSpec(
            name=name,
            written_type=written_type,
            base=base,
            container=container,
            size=size,
            string_bound=int(match["strbound"]) if match["strbound"] else None,
            message_class=None if base in PRIMITIVES else lookup(base),
        )
        if default_text.strip():
            field = FieldSpec(
                **{**field.__dict__, "default": _default(msg_type, field, default_text)}
            )
        fields.append(field)
    return constants, fields


def min_wire_size(fields: list[FieldSpec]) -> int:
    """Fewest bytes a value can take (padding ignored); bounds counts read from the wire."""
    if not fields:
        return 1  # the empty structure's filler byte
    total = 0
    for field in fields:
        if field.message_class is not None:
            element = field.message_class._min_size
        else:
            element = PRIMITIVES[field.base].size
        if field.container == "sequence":
            total += 4
        elif field.container == "array":
            total += element * (field.size or 0)
        else:
            total += element
    return total
