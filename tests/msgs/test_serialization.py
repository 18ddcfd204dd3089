"""Tests for the generated serializers and deserializers: bytes, round trips and errors."""

import copy
import math
import pickle
import struct

import numpy as np
import pytest

from sandbox.msgs import (
    MESSAGE_TYPES,
    DeserializationError,
    Message,
    SerializationError,
    Time,
    geometry_msgs,
    nav_msgs,
    sensor_msgs,
    std_msgs,
)

from .samples import SAMPLES, header, sample


def test_every_hand_written_sample_is_of_a_known_type() -> None:
    assert set(SAMPLES) <= set(MESSAGE_TYPES)


@pytest.mark.parametrize("msg_type", sorted(MESSAGE_TYPES))
def test_sample_round_trips(msg_type: str) -> None:
    message = sample(msg_type)
    cls = MESSAGE_TYPES[msg_type]
    assert type(message) is cls
    data = message.serialize()
    decoded = cls.deserialize(data)
    assert decoded == message
    assert decoded.serialize() == data
    if cls.__slots__:  # the sample really differs from the defaults
        assert decoded != cls()


def test_exact_bytes_of_int32() -> None:
    assert std_msgs.Int32(5).serialize() == b"\x05\x00\x00\x00"
    assert std_msgs.Int32(-1).serialize() == b"\xff\xff\xff\xff"


def test_exact_bytes_of_twist_are_six_little_endian_doubles() -> None:
    twist = geometry_msgs.Twist(
        geometry_msgs.Vector3(1.0, 2.0, 3.0), geometry_msgs.Vector3(4.0, 5.0, 6.0)
    )
    assert twist.serialize() == struct.pack("<6d", 1, 2, 3, 4, 5, 6)


def test_exact_bytes_of_int32_multi_array() -> None:
    data = std_msgs.Int32MultiArray(data=[1, 2]).serialize()
    assert data == struct.pack("<IIIii", 0, 0, 2, 1, 2)


def test_exact_bytes_of_string_and_header() -> None:
    assert std_msgs.String("hé").serialize() == b"\x03\x00\x00\x00h\xc3\xa9"
    stamped = std_msgs.Header(1, Time(2, 3), "map").serialize()
    assert stamped == struct.pack("<IIII", 1, 2, 3, 3) + b"map"


def test_bool_is_one_byte_and_decodes_to_bool() -> None:
    assert std_msgs.Bool(True).serialize() == b"\x01"
    assert std_msgs.Bool.deserialize(b"\x01").data is True


def test_header_stamp_round_trips_as_time() -> None:
    decoded = std_msgs.Header.deserialize(header().serialize())
    assert decoded.stamp == Time(1_700_000_000, 123_456_789)
    assert isinstance(decoded.stamp, Time)


def test_defaults_follow_ros() -> None:
    imu = sensor_msgs.Imu()
    assert imu.orientation_covariance == [0.0] * 9
    assert imu.header.stamp == Time(0, 0) and imu.header.frame_id == ""
    assert geometry_msgs.PoseWithCovariance().covariance == [0.0] * 36
    assert sensor_msgs.LaserScan().ranges == []
    assert std_msgs.Bool().data is False
    assert imu.orientation == geometry_msgs.Quaternion(0.0, 0.0, 0.0, 0.0)


def test_defaults_are_not_shared_between_instances() -> None:
    first, second = sensor_msgs.LaserScan(), sensor_msgs.LaserScan()
    first.ranges.append(1.0)
    first.header.frame_id = "laser"
    assert second.ranges == [] and second.header.frame_id == ""


def test_positional_and_keyword_arguments() -> None:
    assert geometry_msgs.Vector3(1.0, z=3.0) == geometry_msgs.Vector3(x=1.0, y=0.0, z=3.0)
    with pytest.raises(TypeError, match="unexpected keyword argument 'w'"):
        geometry_msgs.Vector3(w=1.0)  # type: ignore[call-arg]
    with pytest.raises(TypeError):
        geometry_msgs.Vector3(1.0, 2.0, 3.0, 4.0)  # type: ignore[call-arg]


def test_numpy_arrays_serialize_like_lists() -> None:
    ranges = np.linspace(0.1, 4.0, 430, dtype=np.float32)
    from_numpy = sensor_msgs.LaserScan(ranges=ranges, intensities=np.zeros(430))
    from_list = sensor_msgs.LaserScan(ranges=ranges.tolist(), intensities=[0.0] * 430)
    assert from_numpy.serialize() == from_list.serialize()
    assert from_numpy == from_list
    cov = np.eye(6).ravel()
    assert geometry_msgs.PoseWithCovariance(covariance=cov).serialize()[-288:] == struct.pack(
        "<36d", *cov
    )


def test_float32_values_are_rounded_to_single_precision() -> None:
    decoded = std_msgs.Float32.deserialize(std_msgs.Float32(0.1).serialize())
    assert decoded.data == struct.unpack("<f", struct.pack("<f", 0.1))[0]
    assert decoded.data != 0.1


def test_nan_and_infinity_serialize() -> None:
    scan = sensor_msgs.LaserScan(ranges=[math.nan, math.inf, -math.inf])
    ranges = sensor_msgs.LaserScan.deserialize(scan.serialize()).ranges
    assert math.isnan(ranges[0]) and ranges[1:] == [math.inf, -math.inf]


def test_occupancy_grid_accepts_bytes_like_and_numpy_int8() -> None:
    cells = np.array([-1, 0, 100], dtype=np.int8)
    grid = nav_msgs.OccupancyGrid(data=cells)
    assert nav_msgs.OccupancyGrid.deserialize(grid.serialize()).data == [-1, 0, 100]


def test_copy_and_pickle_preserve_messages() -> None:
    original = SAMPLES["nav_msgs/Odometry"]()
    assert copy.deepcopy(original) == original
    assert pickle.loads(pickle.dumps(original)) == original


def test_repr_names_fields() -> None:
    assert repr(std_msgs.Int32(3)) == "Int32(data=3)"


# --- serialize() errors name the field --------------------------------------------------------


def test_wrong_type_names_the_field_path() -> None:
    twist = geometry_msgs.Twist()
    twist.linear.x = "fast"
    with pytest.raises(SerializationError) as caught:
        twist.serialize()
    assert str(caught.value) == "geometry_msgs/Twist.linear.x: expected a float, got 'fast' (str)"
    assert isinstance(caught.value, TypeError) and isinstance(caught.value, ValueError)


def test_out_of_range_int_names_the_field() -> None:
    with pytest.raises(SerializationError, match=r"^std_msgs/Int16\.data: 40000 is out of range"):
        std_msgs.Int16(40000).serialize()
    with pytest.raises(SerializationError, match=r"seq: -1 is out of range for uint32"):
        std_msgs.Header(seq=-1).serialize()


@pytest.mark.parametrize(
    ("message", "expected"),
    [
        (std_msgs.Int32(1.5), r"std_msgs/Int32\.data: expected an int, got 1\.5 \(float\)"),
        (std_msgs.String(5), r"std_msgs/String\.data: expected a str, got 5 \(int\)"),
        (std_msgs.Float32(1e300), r"Float32\.data: 1e\+300 is too large for float32"),
        (geometry_msgs.Twist(linear=3), r"Twist\.linear: expected a geometry_msgs/Vector3"),
        (sensor_msgs.Imu(orientation_covariance=[0.0] * 8), r"covariance: expected exactly 9"),
        (sensor_msgs.LaserScan(ranges=[1.0, "x"]), r"LaserScan\.ranges\[1\]: expected a float"),
        (sensor_msgs.LaserScan(ranges=5), r"LaserScan\.ranges: expected a sequence"),
        (std_msgs.Header(stamp=1.5), r"Header\.stamp: expected a Time, got 1\.5"),
        (nav_msgs.OccupancyGrid(data=[200]), r"OccupancyGrid\.data\[0\]: 200 is out of range"),
        (
            nav_msgs.Path(poses=[geometry_msgs.PoseStamped(), geometry_msgs.Pose()]),
            r"Path\.poses\[1\]: expected a geometry_msgs/PoseStamped message",
        ),
    ],
)
def test_serialize_errors_explain(message: Message, expected: str) -> None:
    with pytest.raises(SerializationError, match=expected):
        message.serialize()


def test_fixed_arrays_with_swapped_lengths_are_caught() -> None:
    # 8 + 10 items add up to the right total; the per-array length check must still fire.
    imu = sensor_msgs.Imu(orientation_covariance=[0.0] * 8, angular_velocity_covariance=[0.0] * 10)
    with pytest.raises(SerializationError, match="orientation_covariance: expected exactly 9"):
        imu.serialize()


# --- deserialize() errors name the type --------------------------------------------------------


def test_truncated_int32_says_how_many_bytes() -> None:
    with pytest.raises(DeserializationError) as caught:
        std_msgs.Int32.deserialize(b"\x01\x02")
    assert str(caught.value).startswith("std_msgs/Int32: buffer too short (got 2 bytes, need 4)")


@pytest.mark.parametrize("msg_type", sorted(MESSAGE_TYPES))
def test_every_truncation_is_rejected_with_the_type_name(msg_type: str) -> None:
    data = sample(msg_type).serialize()
    cls = MESSAGE_TYPES[msg_type]
    for length in range(len(data)):
        with pytest.raises(ValueError, match=f"^{msg_type}: buffer too short"):
            cls.deserialize(data[:length])


def test_trailing_bytes_are_rejected() -> None:
    with pytest.raises(DeserializationError, match="std_msgs/Int32: 1 unexpected trailing"):
        std_msgs.Int32.deserialize(b"\x01\x00\x00\x00\x00")


def test_garbage_count_fails_before_allocating() -> None:
    garbage = struct.pack("<IIII", 0, 0, 0, 0) + b"\x00" * 28 + b"\xff\xff\xff\xff"
    with pytest.raises(DeserializationError, match="while reading field 'ranges'"):
        sensor_msgs.LaserScan.deserialize(garbage)


def test_invalid_utf8_is_a_clear_error() -> None:
    with pytest.raises(DeserializationError, match=r"std_msgs/String: .*not valid UTF-8"):
        std_msgs.String.deserialize(b"\x02\x00\x00\x00\xff\xfe")


def test_deserialize_accepts_bytearray_and_memoryview_but_not_str() -> None:
    data = std_msgs.Int32(9).serialize()
    assert std_msgs.Int32.deserialize(bytearray(data)).data == 9
    assert std_msgs.Int32.deserialize(memoryview(data)).data == 9
    with pytest.raises(TypeError, match="needs bytes, got str"):
        std_msgs.Int32.deserialize("abcd")  # type: ignore[arg-type]
