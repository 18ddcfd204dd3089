"""Generate each ROS 2 message class's CDR serializer and deserializer from its fields.

The encoding is OMG DDS-XTypes 1.3, section 7.4.1 ("Extended CDR", encoding version 1, the
classic CDR that Fast-DDS uses for ROS 2), little-endian, preceded by the 4-byte encapsulation
header ``00 01 00 00`` (CDR_LE, options 0) as ``rclpy.serialization.serialize_message`` returns
it. Rules: each primitive is aligned to its own size (8 for 64-bit values) counted from the end
of the header; ``string`` is a uint32 length that counts a terminating NUL, the UTF-8 bytes and
the NUL; a sequence is a uint32 count then its items; a fixed array is its items alone; a
nested structure is its members in order (its alignment is its first member's). Fast-CDR skips
the alignment of an empty primitive sequence's items, and so does rosbags; so do we.

Why generated source: the fields are known when the class is built, so consecutive fixed-size
members (across nesting levels, with their padding known statically) become one precompiled
``struct.Struct``, and numeric sequences move as one ``array.array`` buffer. Where a variable
length member leaves the offset unknown, the generated code pads at run time.

The generated code trusts nothing it reads: every count and length is checked against the bytes
left before anything is allocated, so hostile input fails with ``ShortBuffer``/``BadValue``.
"""

from __future__ import annotations

import struct
import sys
from array import array
from collections.abc import Callable
from typing import Any

from ._spec import NUMPY_DTYPES, PRIMITIVES, FieldSpec

HEADER = b"\x00\x01\x00\x00"  # CDR_LE encapsulation, options 0
_LEN = struct.Struct("<I")
_ZEROS = tuple(bytes(k) for k in range(8))
_LITTLE = sys.byteorder == "little"


class ShortBuffer(Exception):
    """The bytes end before the field at ``path``; the message class makes it a sentence."""

    def __init__(self, need: int, path: str) -> None:
        super().__init__(need, path)
        self.need, self.path = need, path


class BadValue(Exception):
    """A value read from (or about to be written to) the wire breaks a bound of its type."""


def seq_bytes(typecode: str, value: Any) -> bytes:
    """The items of a numeric sequence as little-endian bytes (array.array, numpy, list...)."""
    if value.__class__ is not array or value.typecode != typecode:
        dtype = getattr(value, "dtype", None)
        if dtype is not None:
            return value.astype("<" + typecode, copy=False).tobytes()
        value = array(typecode, value)
    if not _LITTLE:
        value = array(typecode, value)
        value.byteswap()
    return value.tobytes()


def fixed_bytes(dtype: str, size: int, value: Any) -> bytes:
    """A fixed numeric array's items (a numpy array in rosidl's Python, any sequence here)."""
    import numpy

    values = numpy.asarray(value)
    if values.shape != (size,):
        raise BadValue(f"must hold exactly {size} values, got {len(values)}")
    return values.astype(numpy.dtype(dtype).newbyteorder("<"), copy=False).tobytes()


def read_seq(typecode: str, data: bytes, off: int, end: int) -> array:
    values = array(typecode)
    values.frombytes(data[off:end])
    if not _LITTLE:
        values.byteswap()
    return values


def read_fixed(dtype: str, size: int, data: bytes, off: int) -> Any:
    import numpy

    wire = numpy.dtype(dtype).newbyteorder("<")
    return numpy.frombuffer(data, dtype=wire, count=size, offset=off).astype(dtype)


class _Source:
    """Generated lines plus the objects they reference."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.namespace: dict[str, Any] = {
            "_LEN": _LEN,
            "_Z": _ZEROS,
            "_seq_bytes": seq_bytes,
            "_fixed_bytes": fixed_bytes,
            "_read_seq": read_seq,
            "_read_fixed": read_fixed,
            "_Short": ShortBuffer,
            "_Bad": BadValue,
            "_pack": struct.pack,
            "_unpack_from": struct.unpack_from,
        }
        self._counter = 0

    def const(self, prefix: str, value: Any) -> str:
        self._counter += 1
        name = f"{prefix}{self._counter}"
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


class _Writer:
    """Shared state: the alignment known at generation time and the pending struct run.

    ``known`` is the largest power of two (<= 8) for which the offset from the end of the
    header is known modulo ``known``; ``rem`` is that remainder. A run of fixed-size members
    accumulates in ``codes`` (with ``x`` pad bytes where the padding is known) until something
    of variable length forces it out.
    """

    def __init__(self, src: _Source, slots: Callable[[Any, FieldSpec], str]) -> None:
        self.src = src
        self.slots = slots
        self.known, self.rem = 8, 0
        self.codes: list[str] = []

    def unknown(self, known: int = 1) -> None:
        self.known, self.rem = known, 0

    def advance(self, size: int) -> None:
        self.rem = (self.rem + size) % self.known

    def static_pad(self, alignment: int) -> int | None:
        """Pad bytes to reach ``alignment`` if known now, None if only known at run time."""
        if alignment <= 1:
            return 0
        if self.known >= alignment:
            return -self.rem % alignment
        return None


class _SerializerWriter(_Writer):
    def __init__(self, src: _Source, slots: Callable[[Any, FieldSpec], str]) -> None:
        super().__init__(src, slots)
        self.exprs: list[str] = []

    def flush(self, indent: int) -> None:
        if self.codes:
            fmt = "<" + "".join(self.codes)
            if self.exprs:
                packer = self.src.const("_s", struct.Struct(fmt))
                self.src.add(indent, f"buf += {packer}.pack({', '.join(self.exprs)})")
            else:
                self.src.add(indent, f"buf += {bytes(struct.calcsize(fmt))!r}")
            self.codes, self.exprs = [], []

    def align(self, alignment: int, indent: int) -> None:
        pad = self.static_pad(alignment)
        if pad is None:
            self.flush(indent)
            self.src.add(indent, f"buf += _Z[(4 - len(buf)) & {alignment - 1}]")
            self.unknown(alignment)
        elif pad:
            self.codes.append("x" * pad)
            self.advance(pad)

    def fields(self, cls: Any, obj: str, indent: int) -> None:
        specs = cls._field_specs
        if not specs:  # the empty structure's filler byte
            self.codes.append("x")
            self.advance(1)
        for field in specs:
            expr = f"{obj}.{self.slots(cls, field)}"
            if field.container is None:
                self.scalar(field, expr, indent)
            else:
                self.container(field, expr, indent)

    def scalar(self, field: FieldSpec, expr: str, indent: int) -> None:
        if field.message_class is not None:
            self.fields(field.message_class, expr, indent)
            return
        primitive = PRIMITIVES[field.base]
        if field.base == "string":
            self.string(field, expr, indent)
            return
        self.align(primitive.size, indent)
        self.codes.append(primitive.code)
        self.exprs.append(expr)
        self.advance(primitive.size)

    def string(self, field: FieldSpec, expr: str, indent: int) -> None:
        self.align(4, indent)
        self.flush(indent)
        add = self.src.add
        add(indent, f"_b = {expr}.encode()")
        if field.string_bound is not None:
            add(indent, f"if len({expr}) > {field.string_bound}:")
            add(indent + 1, f"raise _Bad('longer than its bound of {field.string_bound}')")
        add(indent, "buf += _LEN.pack(len(_b) + 1)")
        add(indent, "buf += _b")
        add(indent, "buf += b'\\x00'")
        self.unknown()

    def container(self, field: FieldSpec, expr: str, indent: int) -> None:
        add = self.src.add
        primitive = field.primitive
        items = self.src.fresh("_v")
        if field.container == "array" and field.is_numeric_container:
            assert primitive is not None
            self.align(primitive.size, indent)
            self.flush(indent)
            dtype = NUMPY_DTYPES[primitive.typecode]
            add(indent, f"buf += _fixed_bytes({dtype!r}, {field.size}, {expr})")
            self.advance(primitive.size * (field.size or 0))
            return
        self.flush(indent)
        add(indent, f"{items} = {expr}")
        if field.container == "array":
            add(indent, f"if len({items}) != {field.size}:")
            add(indent + 1, f"raise _Bad('must hold exactly {field.size} values')")
        else:
            if field.size is not None:
                add(indent, f"if len({items}) > {field.size}:")
                add(indent + 1, f"raise _Bad('must hold at most {field.size} values')")
            self.align(4, indent)
            self.codes.append("I")
            self.exprs.append(f"len({items})")
            self.advance(4)
            self.flush(indent)
        if field.is_numeric_container:  # a numeric sequence: one buffer
            assert primitive is not None
            pad = self.static_pad(primitive.size)
            if pad != 0:
                add(indent, f"if len({items}):")
                if pad is None:
                    add(indent + 1, f"buf += _Z[(4 - len(buf)) & {primitive.size - 1}]")
                else:
                    add(indent + 1, f"buf += {bytes(pad)!r}")
            add(indent, f"buf += _seq_bytes({primitive.typecode!r}, {items})")
            self.unknown(min(4, primitive.size))
            return
        if primitive is not None and field.base != "string":  # bool and byte items
            add(indent, f"buf += _pack('<%d{primitive.code}' % len({items}), *{items})")
            self.unknown()
            return
        item = self.src.fresh("_e")
        add(indent, f"for {item} in {items}:")
        self.unknown()
        before = len(self.src.lines)
        self.scalar(_element(field), item, indent + 1)
        self.flush(indent + 1)
        if len(self.src.lines) == before:
            add(indent + 1, "pass")
        self.unknown()


def _element(field: FieldSpec) -> FieldSpec:
    return FieldSpec(
        field.name, field.written_type, field.base, None, None, field.string_bound,
        None, field.message_class,
    )  # fmt: skip


def build_serializer(cls: Any, slots: Callable[[Any, FieldSpec], str]) -> Callable[..., bytes]:
    """``_serialize_fast(self) -> bytes``: header and CDR body, unexplained errors."""
    src = _Source()
    src.namespace["_HEADER"] = HEADER
    src.add(0, "def _serialize_fast(self):")
    src.add(1, "buf = bytearray(_HEADER)")
    writer = _SerializerWriter(src, slots)
    writer.fields(cls, "self", 1)
    writer.flush(1)
    src.add(1, "return bytes(buf)")
    return src.compile("_serialize_fast", f"{cls.__name__}._serialize_fast")


class _DeserializerWriter(_Writer):
    def __init__(self, src: _Source, slots: Callable[[Any, FieldSpec], str]) -> None:
        super().__init__(src, slots)
        self.targets: list[str] = []
        self.first_path = ""

    def check(self, indent: int, need: str, path: str) -> None:
        self.src.add(indent, f"if {need} > _n:")
        self.src.add(indent + 1, f"raise _Short({need}, {path!r})")

    def flush(self, indent: int) -> None:
        if not self.codes:
            return
        add = self.src.add
        unpacker = struct.Struct("<" + "".join(self.codes))
        add(indent, f"_end = off + {unpacker.size}")
        self.check(indent, "_end", self.first_path)
        if self.targets:
            name = self.src.const("_s", unpacker)
            targets = ", ".join(self.targets)
            add(indent, f"{targets}, = {name}.unpack_from(data, off)")
        add(indent, "off = _end")
        self.codes, self.targets = [], []

    def align(self, alignment: int, indent: int, path: str) -> None:
        pad = self.static_pad(alignment)
        if pad is None:
            self.flush(indent)
            self.src.add(indent, f"off += (4 - off) & {alignment - 1}")
            self.unknown(alignment)
        elif pad:
            if not self.codes:
                self.first_path = path
            self.codes.append("x" * pad)
            self.advance(pad)

    def fixed(self, code: str, size: int, target: str | None, path: str) -> None:
        if not self.codes:
            self.first_path = path
        self.codes.append(code)
        if target is not None:
            self.targets.append(target)
        self.advance(size)

    def new_message(self, cls: Any, target: str, indent: int) -> str:
        name = self.src.const("_C", cls)
        obj = self.src.fresh("_m")
        self.src.add(indent, f"{obj} = {name}.__new__({name})")
        self.src.add(indent, f"{obj}._check_fields = _CHECK")
        if target:
            self.src.add(indent, f"{target} = {obj}")
        return obj

    def fields(self, cls: Any, obj: str, path: str, indent: int) -> None:
        specs = cls._field_specs
        if not specs:
            self.fixed("x", 1, None, path + "(empty)")
        for field in specs:
            target = f"{obj}.{self.slots(cls, field)}"
            field_path = f"{path}{field.name}"
            if field.container is None:
                self.scalar(field, target, field_path, indent)
            else:
                self.container(field, target, field_path, indent)

    def scalar(self, field: FieldSpec, target: str, path: str, indent: int) -> None:
        add = self.src.add
        if field.message_class is not None:
            # Created before the pending run's unpack line, which then fills it.
            obj = self.new_message(field.message_class, target, indent)
            self.fields(field.message_class, obj, path + ".", indent)
            return
        primitive = PRIMITIVES[field.base]
        if field.base != "string":
            self.align(primitive.size, indent, path)
            self.fixed(primitive.code, primitive.size, target, path)
            return
        self.align(4, indent, path)
        self.flush(indent)
        self.check(indent, "off + 4", path)
        add(indent, "(_cnt,) = _LEN.unpack_from(data, off)")
        add(indent, "_end = off + 4 + _cnt")
        self.check(indent, "_end", path)
        add(indent, f"{target} = data[off + 4 : _end - 1].decode() if _cnt else ''")
        if field.string_bound is not None:
            add(indent, f"if _cnt > {field.string_bound + 1}:")
            add(indent + 1, f"raise _Bad({path!r} + ' is longer than {field.string_bound}')")
        add(indent, "off = _end")
        self.unknown()

    def container(self, field: FieldSpec, target: str, path: str, indent: int) -> None:
        add = self.src.add
        primitive = field.primitive
        if field.container == "array" and field.is_numeric_container:
            assert primitive is not None
            self.align(primitive.size, indent, path)
            self.flush(indent)
            size = primitive.size * (field.size or 0)
            self.check(indent, f"off + {size}", path)
            dtype = NUMPY_DTYPES[primitive.typecode]
            add(indent, f"{target} = _read_fixed({dtype!r}, {field.size}, data, off)")
            add(indent, f"off += {size}")
            self.advance(size)
            return
        if field.container == "array":
            self.flush(indent)
            add(indent, f"_cnt = {field.size}")
        else:
            self.align(4, indent, path)
            self.flush(indent)
            self.check(indent, "off + 4", path)
            add(indent, "(_cnt,) = _LEN.unpack_from(data, off)")
            add(indent, "off += 4")
            self.advance(4)
            if field.size is not None:
                add(indent, f"if _cnt > {field.size}:")
                add(indent + 1, f"raise _Bad({path!r} + ' holds more than {field.size} items')")
        if field.message_class is not None:
            element = field.message_class._min_size
        else:
            assert primitive is not None
            element = primitive.size
        # Bound the count by the bytes left before allocating anything for it.
        self.check(indent, f"off + _cnt * {element}", path)
        if field.is_numeric_container:
            assert primitive is not None
            pad = self.static_pad(primitive.size)
            if pad is None:
                add(indent, "if _cnt:")
                add(indent + 1, f"off += (4 - off) & {primitive.size - 1}")
            elif pad:
                add(indent, "if _cnt:")
                add(indent + 1, f"off += {pad}")
            add(indent, f"_end = off + _cnt * {primitive.size}")
            self.check(indent, "_end", path)
            add(indent, f"{target} = _read_seq({primitive.typecode!r}, data, off, _end)")
            add(indent, "off = _end")
            self.unknown(min(4, primitive.size))
            return
        if primitive is not None and field.base != "string":  # bool and byte items
            add(indent, f"{target} = list(_unpack_from('<%d{primitive.code}' % _cnt, data, off))")
            add(indent, "off += _cnt")
            self.unknown()
            return
        items, item = self.src.fresh("_l"), self.src.fresh("_x")
        add(indent, f"{items} = []")
        add(indent, f"{target} = {items}")
        add(indent, "for _ in range(_cnt):")
        self.unknown()
        if field.message_class is not None:
            obj = self.new_message(field.message_class, item, indent + 1)
            self.fields(field.message_class, obj, path + "[].", indent + 1)
        else:
            self.scalar(_element(field), item, path + "[]", indent + 1)
        self.flush(indent + 1)
        add(indent + 1, f"{items}.append({item})")
        self.unknown()


def build_deserializer(
    cls: Any, slots: Callable[[Any, FieldSpec], str], check_fields: bool
) -> Callable[[bytes], tuple[Any, int]]:
    """``_deserialize_from(data) -> (message, end)``; ``data`` starts with the header."""
    src = _Source()
    src.namespace["_CHECK"] = check_fields
    src.add(0, "def _deserialize_from(data):")
    src.add(1, "_n = len(data)")
    src.add(1, "off = 4")
    writer = _DeserializerWriter(src, slots)
    obj = writer.new_message(cls, "", 1)
    writer.fields(cls, obj, "", 1)
    writer.flush(1)
    src.add(1, f"return {obj}, off")
    return src.compile("_deserialize_from", f"{cls.__name__}._deserialize_from")
