"""Generate a ROS 2 message class's CDR serializer (the rules are in ``_cdr.py``).

Straight-line code appending to one ``bytearray``: runs of fixed-size members with their known
padding become one ``struct.Struct.pack``, numeric sequences one buffer copy, and padding whose
size depends on earlier variable-length members is computed from the buffer's length.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any

from ._cdr import HEADER, Source, Writer, element_of
from ._spec import NUMPY_DTYPES, PRIMITIVES, FieldSpec


class _SerializerWriter(Writer):
    def __init__(self, src: Source, slots: Callable[[Any, FieldSpec], str]) -> None:
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
        self.scalar(element_of(field), item, indent + 1)
        self.flush(indent + 1)
        if len(self.src.lines) == before:
            add(indent + 1, "pass")
        self.unknown()


def build_serializer(cls: Any, slots: Callable[[Any, FieldSpec], str]) -> Callable[..., bytes]:
    """``_serialize_fast(self) -> bytes``: header and CDR body, unexplained errors."""
    src = Source()
    src.namespace["_HEADER"] = HEADER
    src.add(0, "def _serialize_fast(self):")
    src.add(1, "buf = bytearray(_HEADER)")
    writer = _SerializerWriter(src, slots)
    writer.fields(cls, "self", 1)
    writer.flush(1)
    src.add(1, "return bytes(buf)")
    return src.compile("_serialize_fast", f"{cls.__name__}._serialize_fast")
