"""CDR as ROS 2 sends it, and what the generated serializers and deserializers share.

The encoding is OMG DDS-XTypes 1.3, section 7.4.1 ("Extended CDR", encoding version 1, the
classic CDR that Fast-DDS uses for ROS 2), little-endian, preceded by the 4-byte encapsulation
header ``00 01 00 00`` (CDR_LE, options 0) as ``rclpy.serialization.serialize_message`` returns
it. Rules: each primitive is aligned to its own size (8 for 64-bit values) counted from the end
of the header; ``string`` is a uint32 length that counts a terminating NUL, the UTF-8 bytes and
the NUL; a sequence is a uint32 count then its items; a fixed array is its items alone; a
nested structure is its members in order (its alignment is its first member's). Fast-CDR skips
the alignment of an empty primitive sequence's items, and so does rosbags; so do we.

Why generated source (``_cdr_write.py``, ``_cdr_read.py``): the fields are known when the class
is built, so consecutive fixed-size members (across nesting levels, with their padding known
statically) become one precompiled ``struct.Struct``, and numeric sequences move as one
``array.array`` buffer. Where a variable length member leaves the offset unknown, the generated
code pads at run time. ``Writer`` tracks what is known of the offset while generating.
"""

from __future__ import annotations

import struct
import sys
from array import array
from collections.abc import Callable
from typing import Any

from ._spec import FieldSpec

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


class Source:
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


class Writer:
    """Shared state: the alignment known at generation time and the pending struct run.

    ``known`` is the largest power of two (<= 8) for which the offset from the end of the
    header is known modulo ``known``; ``rem`` is that remainder. A run of fixed-size members
    accumulates in ``codes`` (with ``x`` pad bytes where the padding is known) until something
    of variable length forces it out.
    """

    def __init__(self, src: Source, slots: Callable[[Any, FieldSpec], str]) -> None:
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


def element_of(field: FieldSpec) -> FieldSpec:
    return FieldSpec(
        field.name, field.written_type, field.base, None, None, field.string_bound,
        None, field.message_class,
    )  # fmt: skip
