"""rclpy.time.Time and rclpy.duration.Duration: arithmetic, comparison and their TypeErrors,
as rclpy/time.py and duration.py define them (pure: no node needed)."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

import sandbox

ROS_COMPAT2 = Path(sandbox.__file__).parent / "ros_compat2"


@pytest.fixture(scope="module")
def rclpy_time() -> Iterator[tuple]:
    """rclpy.time, rclpy.duration, rclpy.clock_type and builtin_interfaces from ros_compat2;
    forgotten afterwards, so other tests import their own."""
    sys.path.insert(0, str(ROS_COMPAT2))
    before = set(sys.modules)
    try:
        from builtin_interfaces import msg
        from rclpy import clock_type, duration, time

        yield time, duration, clock_type.ClockType, msg
    finally:
        sys.path.remove(str(ROS_COMPAT2))
        for name in set(sys.modules) - before:
            if name.split(".")[0] in ("rclpy", "builtin_interfaces"):
                del sys.modules[name]


def test_time_and_duration_arithmetic(rclpy_time) -> None:
    time, duration, clock_type, _ = rclpy_time
    t = time.Time(seconds=1.5, clock_type=clock_type.ROS_TIME)
    d = duration.Duration(seconds=0.25)
    assert (t + d).nanoseconds == 1_750_000_000
    assert (d + t).nanoseconds == 1_750_000_000
    assert (t - d).nanoseconds == 1_250_000_000
    assert (t - time.Time(seconds=1, clock_type=clock_type.ROS_TIME)) == duration.Duration(
        nanoseconds=500_000_000
    )
    assert (d * 3).nanoseconds == 750_000_000 and (d * 0.5).nanoseconds == 125_000_000
    assert t.seconds_nanoseconds() == (1, 500_000_000)
    assert repr(t) == "Time(nanoseconds=1500000000, clock_type=ROS_TIME)"
    assert str(duration.Duration(seconds=2)) == "2000000000 nanoseconds"


def test_the_type_errors_rclpy_raises(rclpy_time) -> None:
    time, duration, clock_type, _ = rclpy_time
    ros = time.Time(seconds=1, clock_type=clock_type.ROS_TIME)
    system = time.Time(seconds=1)  # SYSTEM_TIME by default: not comparable with the node's
    with pytest.raises(TypeError, match="Can't compare times with different clock types"):
        _ = ros < system
    with pytest.raises(TypeError, match="Can't subtract times with different clock types"):
        _ = ros - system
    with pytest.raises(TypeError):
        _ = ros + ros
    with pytest.raises(TypeError):
        _ = ros < 5.0
    with pytest.raises(TypeError):
        _ = duration.Duration(seconds=1) < 1
    with pytest.raises(ValueError, match="Seconds value must not be negative"):
        time.Time(seconds=-1)
    with pytest.raises(ValueError, match="negative time"):
        _ = time.Time(seconds=1) - duration.Duration(seconds=2)
    with pytest.raises(ValueError, match="nan"):
        _ = duration.Duration(seconds=1) * float("nan")
    with pytest.raises(TypeError):
        hash(ros)  # unhashable, as rclpy's
    assert ros != 1  # equality with a non-Time is simply False


def test_messages_round_trip(rclpy_time) -> None:
    time, duration, clock_type, msg = rclpy_time
    stamp = time.Time(seconds=12, nanoseconds=345, clock_type=clock_type.ROS_TIME).to_msg()
    assert (stamp.sec, stamp.nanosec) == (12, 345)
    back = time.Time.from_msg(stamp)
    assert back.nanoseconds == 12_000_000_345 and back.clock_type == clock_type.ROS_TIME
    negative = duration.Duration(nanoseconds=-1_500_000_000).to_msg()
    assert (negative.sec, negative.nanosec) == (-2, 500_000_000)
    assert duration.Duration.from_msg(msg.Duration(sec=1, nanosec=5)).nanoseconds == 1_000_000_005
    with pytest.raises(TypeError, match=r"builtin_interfaces\.msg\.Time"):
        time.Time.from_msg(msg.Duration())
