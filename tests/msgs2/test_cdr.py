"""CDR bytes against rosbags' serializer (the reference the issue names), round trips, and
hostile input to ``deserialize``."""

from __future__ import annotations

import random
import struct
import time

import pytest
from rosbags.typesys import Stores, get_typestore

from sandbox.msgs import DeserializationError
from sandbox.msgs import get_message_class as get_any_message_class
from sandbox.msgs2 import MESSAGE_TYPES, SerializationError, get_message_class
from tests.msgs2.samples import random_message, to_rosbags

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)
ROSBAGS_TYPES = sorted(name for name in MESSAGE_TYPES if name in TYPESTORE.types)


def test_the_comparison_covers_every_message_package_of_the_type_store() -> None:
    packages = {name.split("/")[0] for name in ROSBAGS_TYPES}
    assert {"std_msgs", "geometry_msgs", "sensor_msgs", "nav_msgs", "tf2_msgs"} <= packages
    assert len(ROSBAGS_TYPES) > 100


@pytest.mark.parametrize("msg_type", ROSBAGS_TYPES)
def test_bytes_match_rosbags_and_round_trip(msg_type: str) -> None:
    cls = get_message_class(msg_type)
    for seed in range(12):
        message = random_message(cls, random.Random(seed))
        ours = message.serialize()
        theirs = bytes(TYPESTORE.serialize_cdr(to_rosbags(message, TYPESTORE), msg_type))
        assert ours == theirs, f"{msg_type} seed {seed}"
        assert cls.deserialize(ours) == message
        # and rosbags reads ours back to the same values
        assert TYPESTORE.serialize_cdr(TYPESTORE.deserialize_cdr(ours, msg_type), msg_type) == ours


def test_known_bytes() -> None:
    Int32 = get_message_class("std_msgs/msg/Int32")
    assert Int32(data=3).serialize() == b"\x00\x01\x00\x00\x03\x00\x00\x00"
    String = get_message_class("std_msgs/msg/String")
    assert String(data="hello").serialize() == bytes.fromhex("00010000 06000000 68656c6c6f00")
    Empty = get_message_class("std_msgs/msg/Empty")
    assert Empty().serialize() == b"\x00\x01\x00\x00\x00"


def test_alignment_counts_from_the_end_of_the_header() -> None:
    # Header.frame_id "a" leaves the offset at 14 (from the data start); the float64 that
    # follows in PointStamped is padded to 16, not to an absolute multiple of 8.
    PointStamped = get_message_class("geometry_msgs/msg/PointStamped")
    message = PointStamped()
    message.header.frame_id = "a"
    message.point.x = 1.0
    data = message.serialize()
    assert data[4 + 8 : 4 + 14] == b"\x02\x00\x00\x00a\x00"
    assert data[4 + 14 : 4 + 16] == b"\x00\x00"
    assert struct.unpack_from("<d", data, 4 + 16) == (1.0,)


def test_non_ascii_strings_and_empty_sequences_round_trip() -> None:
    LaserScan = get_message_class("sensor_msgs/msg/LaserScan")
    scan = LaserScan(ranges=[], intensities=[0.5])
    scan.header.frame_id = "capteur_été_🤖"
    back = LaserScan.deserialize(scan.serialize())
    assert back.header.frame_id == "capteur_été_🤖"
    assert list(back.ranges) == [] and list(back.intensities) == [0.5]


def test_the_ros1_lookup_hands_ros2_names_to_msgs2() -> None:
    cls = get_any_message_class("std_msgs/msg/Int32")
    assert cls is get_message_class("std_msgs/msg/Int32")
    assert cls._schema_encoding == "ros2msg" and cls._message_encoding == "cdr"
    ros1 = get_any_message_class("std_msgs/Int32")
    assert ros1._schema_encoding == "ros1msg" and ros1._message_encoding == "ros1"
    assert cls.deserialize(cls(data=-7).serialize()).data == -7


def _scan_bytes() -> bytes:
    LaserScan = get_message_class("sensor_msgs/msg/LaserScan")
    scan = LaserScan(ranges=[1.0] * 360, intensities=[2.0] * 360)
    scan.header.frame_id = "base_scan"
    return scan.serialize()


def test_every_truncation_is_a_clear_error() -> None:
    LaserScan = get_message_class("sensor_msgs/msg/LaserScan")
    data = _scan_bytes()
    for length in range(len(data)):
        with pytest.raises(DeserializationError, match=r"LaserScan|header"):
            LaserScan.deserialize(data[:length])


@pytest.mark.parametrize("count", [0xFFFFFFFF, 0x7FFFFFFF, 0x10000])
def test_huge_counts_fail_at_once_without_allocating(count: int) -> None:
    LaserScan = get_message_class("sensor_msgs/msg/LaserScan")
    data = bytearray(_scan_bytes())
    offset = 4 + 8 + 4 + 10 + 2 + 7 * 4  # stamp, frame_id "base_scan\0", pad, 7 float32
    assert struct.unpack_from("<I", data, offset) == (360,)
    struct.pack_into("<I", data, offset, count)
    started = time.perf_counter()
    with pytest.raises(DeserializationError, match="ranges"):
        LaserScan.deserialize(bytes(data))
    assert time.perf_counter() - started < 0.1


def test_a_huge_string_length_or_message_count_is_refused() -> None:
    String = get_message_class("std_msgs/msg/String")
    with pytest.raises(DeserializationError, match="data"):
        String.deserialize(b"\x00\x01\x00\x00\xff\xff\xff\xffabc")
    MarkerArray = get_message_class("visualization_msgs/msg/MarkerArray")
    with pytest.raises(DeserializationError, match="markers"):
        MarkerArray.deserialize(b"\x00\x01\x00\x00\xff\xff\xff\x0f" + bytes(64))


def test_headers_other_than_little_endian_cdr_are_refused() -> None:
    Int32 = get_message_class("std_msgs/msg/Int32")
    with pytest.raises(DeserializationError, match="encapsulation header"):
        Int32.deserialize(b"\x03\x00\x00\x00")
    with pytest.raises(DeserializationError, match="big-endian"):
        Int32.deserialize(b"\x00\x00\x00\x00\x00\x00\x00\x03")
    with pytest.raises(DeserializationError, match="trailing"):
        Int32.deserialize(Int32(data=1).serialize() + bytes(8))
    with pytest.raises(DeserializationError, match="UTF-8"):
        get_message_class("std_msgs/msg/String").deserialize(
            b"\x00\x01\x00\x00\x03\x00\x00\x00\xff\xfe\x00"
        )


@pytest.mark.parametrize(
    "msg_type",
    ["sensor_msgs/msg/LaserScan", "nav_msgs/msg/Odometry", "visualization_msgs/msg/MarkerArray",
     "tf2_msgs/msg/TFMessage", "sensor_msgs/msg/PointCloud2"],
)  # fmt: skip
def test_random_garbage_gives_a_message_or_a_deserialization_error(msg_type: str) -> None:
    cls = get_message_class(msg_type)
    rng = random.Random(7)
    valid = random_message(cls, rng).serialize()
    outcomes: list[type] = []
    for _ in range(300):
        data = bytearray(valid)
        for _ in range(rng.randint(1, 6)):
            data[rng.randrange(4, len(data))] = rng.randrange(256)
        cut = rng.choice([len(data), rng.randrange(4, len(data) + 1)])
        try:
            outcomes.append(type(cls.deserialize(bytes(data[:cut]))))
        except DeserializationError:
            outcomes.append(DeserializationError)
    assert set(outcomes) <= {cls, DeserializationError}
    assert DeserializationError in outcomes


def test_a_value_the_wire_cannot_hold_names_the_field() -> None:
    Twist = get_message_class("geometry_msgs/msg/Twist")
    Vector3 = get_message_class("geometry_msgs/msg/Vector3")
    twist = Twist(linear=Vector3(x="fast", check_fields=False))
    with pytest.raises(SerializationError, match=r"Twist\.linear\.x.*float"):
        twist.serialize()
    Int8 = get_message_class("std_msgs/msg/Int8")
    with pytest.raises(SerializationError, match=r"data.*\[-128, 127\]"):
        Int8(data=300, check_fields=False).serialize()
