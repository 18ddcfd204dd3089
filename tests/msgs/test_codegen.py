"""Tests for sandbox.msgs._codegen on field shapes the standard types do not use."""

import struct
import subprocess
import sys

import numpy as np
import pytest

from sandbox.msgs import Duration, Message, SerializationError, Time, geometry_msgs, std_msgs


class KitchenSink(Message, register=False):
    """Every primitive, every array shape, and arrays of strings, times and messages."""

    _type = "test_msgs/KitchenSink"
    _definition = """
bool flag
byte b
char c
int8 i8
uint8 u8
int16 i16
uint16 u16
int32 i32
uint32 u32
int64 i64
uint64 u64
float32 f32
float64 f64
string text
time when
duration span
uint8[] blob
uint8[4] quad
char[] chars
bool[] flags
bool[2] pair
int64[] longs
uint16[3] shorts
string[] words
string[2] two_words
time[] stamps
duration[2] spans
geometry_msgs/Vector3[2] corners
std_msgs/Empty[] nothings
"""


def _full_sink() -> KitchenSink:
    return KitchenSink(
        flag=True,
        b=-128,
        c=255,
        i8=-5,
        u8=200,
        i16=-300,
        u16=60000,
        i32=-70000,
        u32=4_000_000_000,
        i64=-(2**62),
        u64=2**64 - 1,
        f32=0.75,
        f64=1e-300,
        text="ünïcödé",
        when=Time(10, 20),
        span=Duration(-3, 5),
        blob=b"\x00\xffabc",
        quad=bytes([1, 2, 3, 4]),
        chars=b"xy",
        flags=[True, False, True],
        pair=[False, True],
        longs=[-1, 2**40],
        shorts=[1, 2, 65535],
        words=["a", "", "ñ"],
        two_words=["left", "right"],
        stamps=[Time(1, 2), Time(3, 4)],
        spans=[Duration(5), Duration(-6, 7)],
        corners=[geometry_msgs.Vector3(1, 2, 3), geometry_msgs.Vector3(-1, -2, -3)],
        nothings=[std_msgs.Empty(), std_msgs.Empty()],
    )


def test_kitchen_sink_round_trips() -> None:
    sink = _full_sink()
    decoded = KitchenSink.deserialize(sink.serialize())
    assert decoded == sink
    assert decoded.blob == b"\x00\xffabc" and isinstance(decoded.quad, bytes)
    assert decoded.flags == [True, False, True] and decoded.pair[1] is True
    assert decoded.spans[1] == Duration(-6, 7) and isinstance(decoded.stamps[0], Time)
    assert len(decoded.nothings) == 2


def test_kitchen_sink_defaults() -> None:
    sink = KitchenSink()
    assert sink.blob == b"" and sink.quad == b"\x00\x00\x00\x00"
    assert sink.pair == [False, False] and sink.two_words == ["", ""]
    assert sink.spans == [Duration(), Duration()] and sink.spans[0] is not sink.spans[1]
    assert sink.corners[0] is not sink.corners[1]
    assert KitchenSink.deserialize(sink.serialize()) == sink


def test_byte_arrays_equal_lists_of_ints() -> None:
    assert KitchenSink(blob=[1, 2]) == KitchenSink(blob=b"\x01\x02")
    assert KitchenSink(blob=[1, 2]).serialize() == KitchenSink(blob=b"\x01\x02").serialize()


def test_duration_is_signed_on_the_wire() -> None:
    class Span(Message, register=False):
        _type = "test_msgs/Span"
        _definition = "duration d"

    assert Span(Duration(-1, 5)).serialize() == struct.pack("<ii", -1, 5)


def test_numpy_integer_arrays_are_range_checked() -> None:
    with pytest.raises(SerializationError, match=r"longs\[0\]: expected an int, got .*1\.5"):
        KitchenSink(longs=np.array([1.5])).serialize()
    with pytest.raises(SerializationError, match=r"shorts\[0\]: -1 is out of range for uint16"):
        KitchenSink(shorts=np.array([-1, 0, 0])).serialize()
    from_numpy = KitchenSink(longs=np.array([7, -7])).serialize()
    assert from_numpy == KitchenSink(longs=[7, -7]).serialize()


def test_two_dimensional_numpy_array_is_rejected() -> None:
    with pytest.raises(SerializationError, match=r"longs\[0\]: expected an int"):
        KitchenSink(longs=np.zeros((2, 2), dtype=np.int64)).serialize()


def test_time_out_of_range_names_the_part() -> None:
    late = std_msgs.Header(stamp=Time(2**32))
    with pytest.raises(SerializationError, match=r"Header\.stamp\.secs: 4294967296 is out of"):
        late.serialize()


def test_importing_msgs_does_not_import_server() -> None:
    code = "import sys, sandbox.msgs; print(sorted(m for m in sys.modules if m[:6] == 'server'))"
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    assert result.stdout.strip() == "[]"
