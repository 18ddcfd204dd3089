"""Generate each message class's ``__init__``, serializer and deserializer from its parsed fields.

Why generate source instead of interpreting the field list at run time: a serializer written out
as straight-line code, with nested messages inlined and every run of fixed-size primitives
(across nesting levels) packed by one precompiled ``struct.Struct``, is several times faster
than a generic loop. ``geometry_msgs/Twist`` becomes a single ``Struct("<6d").pack(...)``.

The generated serializer does no type checking of its own: ``struct`` rejects wrong types and
out-of-range integers, and ``Message.serialize`` then runs the slow, explaining checker in
``_check.py`` to name the offending field. The deserializer checks every length against the
buffer before reading, so truncated or garbage input fails with a sentence, not a struct error.
"""

from __future__ import annotations

import dataclasses
import struct
import sys
from array import array
from collections.abc import Callable
from typing import Any

from ._spec import FieldSpec
from ._time import Duration, Time

_LEN = struct.Struct("<I")  # string lengths and variable-array counts are uint32
_NUMERIC = ("int", "float", "bool")
_BYTE_CODES = ("B",)  # uint8[] and char[] arrays travel as raw bytes, as in genpy
# struct codes that are also array typecodes of the same item size on this platform; those
# arrays are read in bulk with array.frombytes instead of building a struct format per count.
_ARRAY_CODES = frozenset(
    code for code in "bhHiIqQfd" if array(code).itemsize == struct.calcsize(code)
)


class ShortBuffer(Exception):
    """Raised by generated deserializers; ``Message.deserialize`` turns it into a sentence."""

    def __init__(self, need: int, path: str) -> None:
        super().__init__(need, path)
        self.need = need
        self.path = path


class LengthMismatch(Exception):
    """A fixed-size array has the wrong length; the explaining checker says which one."""


# numpy dtype strings with exactly the wire layout of each struct code.
_NUMPY_WIRE_DTYPES = {
    "b": "|i1",
    "B": "|u1",
    "h": "<i2",
    "H": "<u2",
    "i": "<i4",
    "I": "<u4",
    "q": "<i8",
    "Q": "<u8",
    "f": "<f4",
    "d": "<f8",
}


def pack_array(code: str, values: Any) -> bytes:
    """Count + items of a variable-length numeric array (any sequence, numpy arrays too)."""
    count = len(values)
    if code == "B" and isinstance(values, bytes | bytearray):
        return _LEN.pack(count) + values
    dtype = getattr(values, "dtype", None)
    if dtype is not None and getattr(values, "ndim", 0) == 1:
        wire = _NUMPY_WIRE_DTYPES[code]
        # Same-layout integers, or floats into a float field (narrowing like struct does): copy
        # the buffer directly. Other dtypes take the checked path below.
        if dtype.str == wire or (dtype.kind == "f" and wire[1] == "f"):
            return _LEN.pack(count) + values.astype(wire, copy=False).tobytes()
    if values.__class__ is not list and values.__class__ is not tuple:
        # numpy/array.array: tolist() gives Python numbers in one C call, faster than iterating.
        tolist = getattr(values, "tolist", None)
        values = tolist() if tolist is not None else list(values)
    return _LEN.pack(count) + struct.pack(f"<{count}{code}", *values)


def read_array(code: str, data: bytes, offset: int, count: int, kind: str) -> Any:
    """Decode ``count`` numeric items at ``offset``: bytes for uint8, bools or a list otherwise."""
    if code == "B" and kind != "bool":
        return data[offset : offset + count * 1]
    if code not in _ARRAY_CODES:
        items: list[Any] = list(struct.unpack_from(f"<{count}{code}", data, offset))
    else:
        values = array(code)
        values.frombytes(data[offset : offset + count * values.itemsize])
        if sys.byteorder != "little":
            values.byteswap()
        items = values.tolist()
    return [bool(item) for item in items] if kind == "bool" else items


class _Source:
    """Accumulates generated lines and the constants they reference."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.namespace: dict[str, Any] = {
            "_LEN": _LEN,
            "_pack_array": pack_array,
            "_read_array": read_array,
            "_ShortBuffer": ShortBuffer,
            "_LengthMismatch": LengthMismatch,
            "_Time": Time,
            "_Duration": Duration,
            "_D": _DEFAULT,
        }
        self._counter = 0

    def const(self, prefix: str, value: Any) -> str:
        name = f"{prefix}{self._counter}"
        self._counter += 1
        self.namespace[name] = value
        return name

    def fresh(self, prefix: str) -> str:
        self._counter += 1
        return f"{prefix}{self._counter}"

    def add(self, indent: int, line: str) -> None:
        self.lines.append("    " * indent + line)

    def compile(self, func_name: str, qualname: str) -> Callable[..., Any]:
        source = "\n".join(self.lines) + "\n"
        exec(compile(source, f"<generated {qualname}>", "exec"), self.namespace)
        func = self.namespace[func_name]
        func.__qualname__ = qualname
        return func


_DEFAULT = object()  # sentinel for "argument not given" in generated __init__ signatures


def _element(field: FieldSpec) -> FieldSpec:
    return dataclasses.replace(field, is_array=False, array_len=None)


class _SerializerWriter:
    """Emits ``_append(...)`` calls, merging consecutive fixed-size values into one Struct."""

    def __init__(self, src: _Source) -> None:
        self.src = src
        self.codes: list[str] = []
        self.exprs: list[str] = []

    def flush(self, indent: int) -> None:
        if self.codes:
            packer = self.src.const("_s", struct.Struct("<" + "".join(self.codes)))
            self.src.add(indent, f"_append({packer}.pack({', '.join(self.exprs)}))")
            self.codes, self.exprs = [], []

    def fields(self, specs: tuple[FieldSpec, ...], obj: str, indent: int, depth: int) -> None:
        for field in specs:
            expr = f"{obj}.{field.name}"
            if field.is_array:
                self.array(field, expr, indent, depth)
            else:
                self.scalar(field, expr, indent, depth)

    def scalar(self, field: FieldSpec, expr: str, indent: int, depth: int) -> None:
        kind = field.kind
        if kind in _NUMERIC:
            self.codes.append(field.code)
            self.exprs.append(expr)
        elif kind in ("time", "duration"):
            self.codes.append(field.code)
            self.exprs += [f"{expr}.secs", f"{expr}.nsecs"]
        elif kind == "string":
            self.flush(indent)
            self.src.add(indent, f"_v = {expr}")
            # str.encode for text; bytes pass through; anything else fails in bytes.__add__.
            self.src.add(indent, "_b = _v.encode() if _v.__class__ is str else b'' + _v")
            self.src.add(indent, "_append(_LEN.pack(len(_b)))")
            self.src.add(indent, "_append(_b)")
        else:
            self.fields(field.message_class._field_specs, expr, indent, depth)

    def array(self, field: FieldSpec, expr: str, indent: int, depth: int) -> None:
        if field.kind in _NUMERIC:
            if field.array_len is None:
                self.flush(indent)
                self.src.add(indent, f"_append(_pack_array({field.code!r}, {expr}))")
            else:
                self.src.add(indent, f"if len({expr}) != {field.array_len}:")
                self.src.add(indent + 1, "raise _LengthMismatch")
                self.codes.append(field.code * field.array_len)
                self.exprs.append(f"*{expr}")
            return
        self.flush(indent)
        items, item = f"_a{depth}", f"_e{depth}"
        self.src.add(indent, f"{items} = {expr}")
        if field.array_len is None:
            self.src.add(indent, f"_append(_LEN.pack(len({items})))")
        else:
            self.src.add(indent, f"if len({items}) != {field.array_len}:")
            self.src.add(indent + 1, "raise _LengthMismatch")
        self.src.add(indent, f"for {item} in {items}:")
        before = len(self.src.lines)
        self.scalar(_element(field), item, indent + 1, depth + 1)
        self.flush(indent + 1)
        if len(self.src.lines) == before:  # e.g. an array of std_msgs/Empty
            self.src.add(indent + 1, "pass")


def build_serializer(cls: type) -> Callable[[Any], bytes]:
    """``_serialize_fast(self) -> bytes`` for ``cls``, without explanations on failure."""
    src = _Source()
    src.add(0, "def _serialize_fast(self):")
    src.add(1, "_parts = []")
    src.add(1, "_append = _parts.append")
    writer = _SerializerWriter(src)
    writer.fields(cls._field_specs, "self", 1, 0)
    writer.flush(1)
    src.add(1, "return b''.join(_parts)")
    return src.compile("_serialize_fast", f"{cls.__name__}._serialize_fast")


class _DeserializerWriter:
    """Emits bounds-checked reads; consecutive fixed-size values are one ``unpack_from``."""

    def __init__(self, src: _Source) -> None:
        self.src = src
        self.codes: list[str] = []
        self.targets: list[tuple[str, FieldSpec]] = []
        self.first_path = ""

    def check(self, indent: int, need: str, path: str) -> None:
        self.src.add(indent, f"if {need} > _n:")
        self.src.add(indent + 1, f"raise _ShortBuffer({need}, {path!r})")

    def flush(self, indent: int) -> None:
        if not self.codes:
            return
        unpacker = self.src.const("_s", struct.Struct("<" + "".join(self.codes)))
        add = self.src.add
        add(indent, f"_end = off + {unpacker}.size")
        self.check(indent, "_end", self.first_path)
        add(indent, f"_t = {unpacker}.unpack_from(data, off)")
        add(indent, "off = _end")
        index = 0
        for target, field in self.targets:
            kind = field.kind
            if field.is_array:
                stop = index + field.array_len
                if field.code == "B" and kind != "bool":
                    add(indent, f"{target} = bytes(_t[{index}:{stop}])")
                elif kind == "bool":
                    add(indent, f"{target} = [bool(_x) for _x in _t[{index}:{stop}]]")
                else:
                    add(indent, f"{target} = list(_t[{index}:{stop}])")
                index = stop
            elif kind in ("time", "duration"):
                cls = "_Time" if kind == "time" else "_Duration"
                add(indent, f"{target} = {cls}(_t[{index}], _t[{index + 1}])")
                index += 2
            else:
                value = f"_t[{index}]"
                add(indent, f"{target} = {f'bool({value})' if kind == 'bool' else value}")
                index += 1
        self.codes, self.targets = [], []

    def fields(self, specs: tuple[FieldSpec, ...], obj: str, path: str, indent: int) -> None:
        for field in specs:
            target, field_path = f"{obj}.{field.name}", f"{path}{field.name}"
            if field.is_array:
                self.array(field, target, field_path, indent)
            else:
                self.scalar(field, target, field_path, indent)

    def _read_count(self, indent: int, path: str) -> None:
        self.flush(indent)
        self.check(indent, "off + 4", path)
        self.src.add(indent, "(_cnt,) = _LEN.unpack_from(data, off)")
        self.src.add(indent, "off += 4")

    def scalar(self, field: FieldSpec, target: str, path: str, indent: int) -> None:
        kind = field.kind
        if kind == "message":
            cls = self.src.const("_C", field.message_class)
            obj = self.src.fresh("_m")
            self.src.add(indent, f"{obj} = {cls}.__new__({cls})")
            self.src.add(indent, f"{target} = {obj}")
            self.fields(field.message_class._field_specs, obj, path + ".", indent)
        elif kind == "string":
            self._read_count(indent, path)
            self.src.add(indent, "_end = off + _cnt")
            self.check(indent, "_end", path)
            self.src.add(indent, f"{target} = data[off:_end].decode()")
            self.src.add(indent, "off = _end")
        else:
            if not self.codes:
                self.first_path = path
            self.codes.append(field.code)
            self.targets.append((target, field))

    def array(self, field: FieldSpec, target: str, path: str, indent: int) -> None:
        add = self.src.add
        if field.kind in _NUMERIC and field.array_len is not None:
            if not self.codes:
                self.first_path = path
            self.codes.append(field.code * field.array_len)
            self.targets.append((target, field))
            return
        if field.array_len is None:
            self._read_count(indent, path)
        else:
            self.flush(indent)
            add(indent, f"_cnt = {field.array_len}")
        element_size = struct.calcsize("<" + field.code) if field.kind in _NUMERIC else 0
        if field.kind == "message":
            element_size = field.message_class._min_size
        elif field.kind == "string":
            element_size = 4
        elif field.kind in ("time", "duration"):
            element_size = 8
        # Bound the count by the bytes left before looping, so a garbage count fails at once.
        self.check(indent, f"off + _cnt * {element_size}", path)
        if field.kind in _NUMERIC:
            call = f"_read_array({field.code!r}, data, off, _cnt, {field.kind!r})"
            add(indent, f"{target} = {call}")
            add(indent, f"off += _cnt * {element_size}")
            return
        items, counter, item = self.src.fresh("_l"), self.src.fresh("_i"), self.src.fresh("_x")
        add(indent, f"{items} = []")
        add(indent, f"{target} = {items}")
        add(indent, f"for {counter} in range(_cnt):")
        element = _element(field)
        if element.kind == "message":
            cls = self.src.const("_C", field.message_class)
            add(indent + 1, f"{item} = {cls}.__new__({cls})")
            self.fields(field.message_class._field_specs, item, path + "[].", indent + 1)
        else:
            self.scalar(element, item, path + "[]", indent + 1)
        self.flush(indent + 1)
        add(indent + 1, f"{items}.append({item})")


def build_deserializer(cls: type) -> Callable[[bytes], tuple[Any, int]]:
    """``_deserialize_from(data) -> (message, end_offset)``; raises ShortBuffer when truncated."""
    src = _Source()
    root = src.const("_C", cls)
    src.add(0, "def _deserialize_from(data):")
    src.add(1, "_n = len(data)")
    src.add(1, "off = 0")
    src.add(1, f"_m0 = {root}.__new__({root})")
    writer = _DeserializerWriter(src)
    writer.fields(cls._field_specs, "_m0", "", 1)
    writer.flush(1)
    src.add(1, "return _m0, off")
    return src.compile("_deserialize_from", f"{cls.__name__}._deserialize_from")


def _default_expr(src: _Source, field: FieldSpec) -> str:
    """Source of a fresh ROS default value for ``field`` (new objects on every call)."""
    kind = field.kind
    if kind == "message":
        one = f"{src.const('_C', field.message_class)}()"
    elif kind in ("time", "duration"):
        one = "_Time()" if kind == "time" else "_Duration()"
    else:
        one = {"int": "0", "float": "0.0", "bool": "False", "string": "''"}[kind]
    byte_array = field.code in _BYTE_CODES and kind == "int"
    if not field.is_array:
        return one
    if field.array_len is None:
        return "b''" if byte_array else "[]"
    if byte_array:
        return f"bytes({field.array_len})"
    if kind in ("message", "time", "duration"):
        return f"[{one} for _ in range({field.array_len})]"
    return f"[{one}] * {field.array_len}"


def build_init(cls: type) -> Callable[..., None]:
    """``__init__(self, field=default, ...)`` accepting positional or keyword values."""
    src = _Source()
    params = "".join(f", {field.name}=_D" for field in cls._field_specs)
    src.add(0, f"def __init__(self{params}):")
    for field in cls._field_specs:
        default = _default_expr(src, field)
        src.add(1, f"self.{field.name} = {default} if {field.name} is _D else {field.name}")
    if not cls._field_specs:
        src.add(1, "pass")
    return src.compile("__init__", f"{cls.__name__}.__init__")
