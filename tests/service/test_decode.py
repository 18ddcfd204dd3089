"""decode/to_jsonable: every message becomes data that strict JSON accepts, quickly."""

from __future__ import annotations

import json
import math
import time

import numpy as np
import pytest

from sandbox.msgs import MESSAGE_TYPES, Message, Time, UnknownMessageTypeError, get_message_class
from sandbox.msgs.geometry_msgs import Twist, Vector3
from sandbox.msgs.nav_msgs import OccupancyGrid, Odometry
from sandbox.msgs.sensor_msgs import LaserScan
from sandbox.msgs.std_msgs import (
    Float32MultiArray,
    Float64,
    Header,
    Int32,
    Int32MultiArray,
    MultiArrayDimension,
    MultiArrayLayout,
)
from server.service.decode import MAX_ARRAY_ITEMS, decode, to_jsonable


class Blob(Message, register=False):
    _type = "test_msgs/Blob"
    _definition = """
uint8[] payload
uint8[4] fixed
time[] stamps
string[] names
"""


def strict_json(data: object) -> object:
    """What a browser's JSON.parse would get; raises on NaN/inf like it would."""
    return json.loads(json.dumps(data, allow_nan=False))


def laser_scan(beams: int = 429) -> LaserScan:
    ranges = [0.5 + 0.01 * i for i in range(beams)]
    ranges[3] = math.inf  # no return
    ranges[7] = math.nan
    return LaserScan(
        header=Header(seq=4, stamp=Time(12, 500_000_000), frame_id="laser"),
        angle_min=-math.pi,
        angle_max=math.pi,
        angle_increment=2 * math.pi / beams,
        range_min=0.12,
        range_max=3.5,
        ranges=ranges,
        intensities=[],
    )


def test_int32() -> None:
    assert decode("std_msgs/Int32", Int32(data=5).serialize()) == {"data": 5}


def test_laser_scan_non_finite_ranges_become_none() -> None:
    decoded = strict_json(decode("sensor_msgs/LaserScan", laser_scan().serialize()))
    assert decoded["header"] == {"seq": 4, "stamp": 12.5, "frame_id": "laser"}
    assert len(decoded["ranges"]) == 429
    assert decoded["ranges"][3] is None and decoded["ranges"][7] is None
    assert decoded["ranges"][0] == pytest.approx(0.5)
    assert decoded["intensities"] == []
    assert decoded["range_max"] == pytest.approx(3.5)


def test_laser_scan_decodes_well_under_a_millisecond() -> None:
    data = laser_scan().serialize()
    decode("sensor_msgs/LaserScan", data)  # plan the class once
    timings = []
    for _ in range(200):
        start = time.perf_counter()
        decode("sensor_msgs/LaserScan", data)
        timings.append(time.perf_counter() - start)
    assert sorted(timings)[len(timings) // 2] < 0.5e-3  # [s] median


def test_int32_multi_array_with_layout() -> None:
    message = Int32MultiArray(
        layout=MultiArrayLayout(
            dim=[MultiArrayDimension(label="row", size=2, stride=4)], data_offset=1
        ),
        data=[1, -2, 3, 2**31 - 1],
    )
    assert decode("std_msgs/Int32MultiArray", message.serialize()) == {
        "layout": {"dim": [{"label": "row", "size": 2, "stride": 4}], "data_offset": 1},
        "data": [1, -2, 3, 2**31 - 1],
    }


def test_twist() -> None:
    message = Twist(linear=Vector3(x=0.2), angular=Vector3(z=-1.5))
    assert decode("geometry_msgs/Twist", message.serialize()) == {
        "linear": {"x": pytest.approx(0.2), "y": 0.0, "z": 0.0},
        "angular": {"x": 0.0, "y": 0.0, "z": -1.5},
    }


def test_odometry_fixed_covariance_is_a_list() -> None:
    message = Odometry(child_frame_id="base_link")
    message.pose.covariance = tuple(float(i) for i in range(36))
    message.pose.pose.position.x = 1.25
    decoded = strict_json(decode("nav_msgs/Odometry", message.serialize()))
    assert decoded["child_frame_id"] == "base_link"
    assert decoded["pose"]["covariance"] == [float(i) for i in range(36)]
    assert decoded["pose"]["pose"]["position"]["x"] == 1.25
    assert decoded["twist"]["covariance"] == [0.0] * 36


def test_nan_and_inf_scalars_become_none() -> None:
    for value in (math.nan, math.inf, -math.inf):
        assert decode("std_msgs/Float64", Float64(data=value).serialize()) == {"data": None}


def test_user_built_numpy_tuple_and_bytes_values() -> None:
    floats = Float32MultiArray(data=np.array([1.0, np.nan, 2.5], dtype=np.float32))
    assert strict_json(to_jsonable(floats))["data"] == [1.0, None, 2.5]
    ints = Int32MultiArray(data=np.arange(3, dtype=np.int32))
    assert to_jsonable(ints)["data"] == [0, 1, 2]
    assert to_jsonable(Int32(data=np.int32(7))) == {"data": 7}
    blob = Blob(payload=b"\x00\xff", fixed=(1, 2, 3, 4), stamps=[Time(1, 5)], names=("a",))
    assert strict_json(to_jsonable(blob)) == {
        "payload": [0, 255],
        "fixed": [1, 2, 3, 4],
        "stamps": [1.000000005],
        "names": ["a"],
    }
    decoded = strict_json(decode_blob(blob))
    assert decoded["payload"] == [0, 255] and decoded["fixed"] == [1, 2, 3, 4]


def decode_blob(blob: Blob) -> dict:
    return to_jsonable(Blob.deserialize(blob.serialize()))


def test_output_does_not_alias_the_message() -> None:
    message = Int32MultiArray(data=[1, 2])
    decoded = to_jsonable(message)
    message.data.append(3)
    assert decoded["data"] == [1, 2]


def test_huge_arrays_are_omitted_with_their_count() -> None:
    cells = 200 * 200
    assert cells > MAX_ARRAY_ITEMS
    grid = OccupancyGrid(data=[0] * cells)
    grid.info.width = grid.info.height = 200
    decoded = decode("nav_msgs/OccupancyGrid", grid.serialize())
    assert decoded["data"] == {"omitted_items": cells}
    assert decoded["info"]["width"] == 200
    small = OccupancyGrid(data=[-1] * MAX_ARRAY_ITEMS)
    assert to_jsonable(small)["data"] == [-1] * MAX_ARRAY_ITEMS


@pytest.mark.parametrize("type_name", sorted(MESSAGE_TYPES))
def test_every_registered_type_round_trips_to_strict_json(type_name: str) -> None:
    cls = get_message_class(type_name)
    decoded = strict_json(decode(type_name, cls().serialize()))
    assert list(decoded) == list(cls.__slots__)


def test_unknown_type_names_the_known_ones() -> None:
    with pytest.raises(UnknownMessageTypeError, match="std_msgs/Int32"):
        decode("std_msgs/Nope", b"")
