"""Generate a ROS 2 message class's CDR deserializer (the rules are in ``_cdr.py``).

Straight-line code reading from ``bytes`` at a running offset: objects are created with
``__new__`` and their slots filled directly (no setters), runs of fixed-size members come from
one ``unpack_from``, numeric sequences from one ``array.frombytes``. Every length and count is
checked against the bytes left before it is used, so hostile input raises ``ShortBuffer`` or
``BadValue`` (``Message.deserialize`` makes them a sentence) and never allocates more than the
input's size.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any

from ._cdr import Source, Writer, element_of
from ._spec import NUMPY_DTYPES, PRIMITIVES, FieldSpec


class _DeserializerWriter(Writer):
    def __init__(self, src: Source, slots: Callable[[Any, FieldSpec], str]) -> None:
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
            self.scalar(element_of(field), item, path + "[]", indent + 1)
        self.flush(indent + 1)
        add(indent + 1, f"{items}.append({item})")
        self.unknown()


def build_deserializer(
    cls: Any, slots: Callable[[Any, FieldSpec], str], check_fields: bool
) -> Callable[[bytes], tuple[Any, int]]:
    """``_deserialize_from(data) -> (message, end)``; ``data`` starts with the header."""
    src = Source()
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
