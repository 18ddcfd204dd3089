"""decode/to_jsonable for a ROS 2 run's messages ("pkg/msg/Name", CDR): ROS 2 field names, a
stamp as {sec, nanosec} as `ros2 topic echo` shows it, strict JSON whatever the values."""

from __future__ import annotations

import json
import math

import pytest

from sandbox.msgs2 import MESSAGE_TYPES, get_message_class
from server.service.decode import decode


def strict_json(data: object) -> object:
    return json.loads(json.dumps(data, allow_nan=False))


def test_a_laser_scan_keeps_its_ros2_fields_and_its_gaps():
    scan = get_message_class("sensor_msgs/msg/LaserScan")(range_max=3.5)
    scan.header.stamp.sec, scan.header.stamp.nanosec = 12, 500_000_000
    scan.header.frame_id = "base_scan"
    scan.ranges = [0.5, math.inf, math.nan, 1.25]
    decoded = strict_json(decode("sensor_msgs/msg/LaserScan", scan.serialize()))
    assert decoded["header"] == {
        "stamp": {"sec": 12, "nanosec": 500_000_000},
        "frame_id": "base_scan",
    }
    assert decoded["ranges"] == [0.5, None, None, 1.25]
    assert decoded["range_max"] == 3.5


def test_bytes_and_fixed_arrays_become_numbers():
    byte = get_message_class("std_msgs/msg/Byte")(data=b"\x07")
    assert decode("std_msgs/msg/Byte", byte.serialize()) == {"data": 7}
    odom = get_message_class("nav_msgs/msg/Odometry")()
    odom.pose.covariance[0] = 0.25
    decoded = strict_json(decode("nav_msgs/msg/Odometry", odom.serialize()))
    assert decoded["pose"]["covariance"][:2] == [0.25, 0.0]
    assert len(decoded["pose"]["covariance"]) == 36


@pytest.mark.parametrize("type_name", [name for name in sorted(MESSAGE_TYPES) if "/msg/" in name])
def test_every_ros2_message_type_round_trips_to_strict_json(type_name: str) -> None:
    cls = get_message_class(type_name)
    decoded = strict_json(decode(type_name, cls().serialize()))
    assert list(decoded) == list(cls.get_fields_and_field_types())
