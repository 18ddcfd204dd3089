"""ROS 1 <-> ROS 2 message conversion at the robot's edge (sandbox/msgs2/bridge.py)."""

from __future__ import annotations

import time

import pytest

from sandbox.msgs import MESSAGE_TYPES as ROS1_TYPES
from sandbox.msgs import Duration, Time
from sandbox.msgs import get_message_class as ros1_class
from sandbox.msgs2 import MESSAGE_TYPES, get_message_class
from sandbox.msgs2.bridge import BridgeError, ros1_name, ros2_name, to_ros1, to_ros2
from tests.msgs.samples import sample

TWINNED = sorted(name for name in ROS1_TYPES if ros2_name(name) in MESSAGE_TYPES)


def test_names() -> None:
    assert ros2_name("std_msgs/Int32") == "std_msgs/msg/Int32"
    assert ros1_name("std_msgs/msg/Int32") == "std_msgs/Int32"
    assert ros2_name("std_srvs/SetBoolRequest") == "std_srvs/srv/SetBool_Request"
    assert ros1_name("std_srvs/srv/SetBool_Response") == "std_srvs/SetBoolResponse"
    with pytest.raises(BridgeError, match="package/Name"):
        ros2_name("std_msgs/msg/Int32")


def test_most_ros1_types_have_a_twin() -> None:
    assert {"sensor_msgs/LaserScan", "nav_msgs/Odometry", "tf2_msgs/TFMessage"} <= set(TWINNED)
    assert len(TWINNED) > 90


@pytest.mark.parametrize("ros1_type", TWINNED)
def test_every_twinned_type_survives_the_round_trip(ros1_type: str) -> None:
    original = sample(ros1_type)
    converted = to_ros2(original)
    assert converted._type == ros2_name(ros1_type)
    converted.serialize()  # the values are legal ROS 2 values
    back = to_ros1(converted)
    assert _seqs(back) == [0] * len(_seqs(original))  # Header.seq is gone in ROS 2, 0 back
    _zero_seqs(original)
    assert back == original


def _headers(message: object) -> list[object]:
    found = [message] if message._type == "std_msgs/Header" else []  # type: ignore[attr-defined]
    for field in message._field_specs:  # type: ignore[attr-defined]
        if field.message_class is not None:
            value = getattr(message, field.name)
            for item in value if field.is_array else [value]:
                found += _headers(item)
    return found


def _seqs(message: object) -> list[int]:
    return [header.seq for header in _headers(message)]  # type: ignore[attr-defined]


def _zero_seqs(message: object) -> None:
    for header in _headers(message):
        header.seq = 0  # type: ignore[attr-defined]


def test_header_and_time_mapping() -> None:
    scan = ros1_class("sensor_msgs/LaserScan")(ranges=[1.0, 2.5])
    scan.header.seq = 41
    scan.header.stamp = Time(1_700_000_000, 5)
    scan.header.frame_id = "base_scan"
    ros2 = to_ros2(scan)
    assert not hasattr(ros2.header, "seq")
    assert (ros2.header.stamp.sec, ros2.header.stamp.nanosec) == (1_700_000_000, 5)
    assert list(ros2.ranges) == [1.0, 2.5] and ros2.ranges.typecode == "f"
    assert repr(ros2).startswith("sensor_msgs.msg.LaserScan(header=std_msgs.msg.Header(")
    marker = ros1_class("visualization_msgs/Marker")(lifetime=Duration(-1, 500_000_000))
    lifetime = to_ros2(marker).lifetime
    assert (lifetime.sec, lifetime.nanosec) == (-1, 500_000_000)


def test_ros2_only_fields_get_defaults_and_are_left_out_coming_back() -> None:
    Range = get_message_class("sensor_msgs/msg/Range")
    converted = to_ros2(ros1_class("sensor_msgs/Range")(range=1.5))
    assert converted.variance == 0.0 and converted.range == 1.5
    assert to_ros1(Range(range=2.0, variance=0.1)).range == 2.0


def test_a_twist_stamped_can_drive_a_ros1_twist_robot() -> None:
    TwistStamped = get_message_class("geometry_msgs/msg/TwistStamped")
    command = TwistStamped()
    command.twist.linear.x = 0.22
    command.twist.angular.z = -1.0
    twist = to_ros1(command, "geometry_msgs/Twist")
    assert type(twist) is ros1_class("geometry_msgs/Twist")
    assert (twist.linear.x, twist.angular.z) == (0.22, -1.0)


def test_what_does_not_map_is_a_sentence() -> None:
    with pytest.raises(BridgeError, match="actionlib_msgs/GoalID has no ROS 2 counterpart"):
        to_ros2(ros1_class("actionlib_msgs/GoalID")())
    with pytest.raises(BridgeError, match="cannot become a ROS 1 std_msgs/Int32"):
        to_ros1(get_message_class("geometry_msgs/msg/Twist")(), "std_msgs/Int32")
    stamp = get_message_class("builtin_interfaces/msg/Time")(sec=-5)
    with pytest.raises(BridgeError, match="negative"):
        to_ros1(get_message_class("std_msgs/msg/Header")(stamp=stamp))


def test_a_scan_converts_well_within_a_10_hz_budget() -> None:
    scan = ros1_class("sensor_msgs/LaserScan")(ranges=[1.0] * 360, intensities=[1.0] * 360)
    to_ros2(scan)
    started = time.perf_counter()
    for _ in range(100):
        to_ros1(to_ros2(scan))
    per_round_trip = (time.perf_counter() - started) / 100
    assert per_round_trip < 0.005  # [s]; measured ~35 us, the period is 100 ms


def test_numpy_values_from_the_simulator_convert() -> None:
    import numpy

    scan = ros1_class("sensor_msgs/LaserScan")(
        ranges=numpy.linspace(0.5, 2.0, 4, dtype=numpy.float32), intensities=numpy.ones(4)
    )
    converted = to_ros2(scan)
    assert list(converted.ranges) == [0.5, 1.0, 1.5, 2.0] and converted.ranges.typecode == "f"
    assert list(converted.intensities) == [1.0] * 4 and converted.intensities.typecode == "f"
    grid = ros1_class("nav_msgs/OccupancyGrid")(data=numpy.array([-1, 0, 100], dtype=numpy.int8))
    assert list(to_ros2(grid).data) == [-1, 0, 100]
    get_message_class("nav_msgs/msg/OccupancyGrid").deserialize(to_ros2(grid).serialize())
