"""What differs between ROS 1's and ROS 2's tf2 Python API, so that one buffer core serves both.

ROS 1 (tf2_py for rospy): times are rospy.Time / rospy.Duration (to_nsec()), the result is a
geometry_msgs/TransformStamped whose header.stamp is a rospy.Time.
ROS 2 (ros2/geometry2 tf2_py/src/tf2_py.cpp): a time is anything with `sec` and `nanosec`
(builtin_interfaces/Time or Duration) or with `nanoseconds` (rclpy.time.Time and
rclpy.duration.Duration); the result is a geometry_msgs/msg/TransformStamped stamped with a
builtin_interfaces/Time, and get_latest_common_time returns an rclpy Time. Otherwise tf2_py
says "time must have sec and nanosec, or nanoseconds.".
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from sandbox.msgs import Duration, Time
from sandbox.units import NS_PER_S


@dataclass(frozen=True)
class Dialect:
    """How one ROS version spells times and transforms to the buffer core."""

    transform_type: str  # the TransformStamped message type name
    to_nsec: Callable[[Any, str], int]  # (time or duration, what is asking) -> nanoseconds
    stamp: Callable[[int], Any]  # nanoseconds -> a header.stamp value
    time: Callable[[int], Any]  # nanoseconds -> the API's Time (get_latest_common_time)
    duration: Callable[[int], Any]  # nanoseconds -> the API's Duration (cache_time)
    timeout_example: str  # a timeout as a student writes it, for hints


def ros1_nsec(value: Any, what: str) -> int:
    """Integer nanoseconds of a rospy.Time or rospy.Duration."""
    if hasattr(value, "to_nsec"):
        return int(value.to_nsec())
    if hasattr(value, "to_sec"):
        return round(float(value.to_sec()) * NS_PER_S)
    raise TypeError(
        f"{what} takes a rospy.Time (rospy.Time(0) for the latest transform) or a "
        f"rospy.Duration, got {value!r}"
    )


def ros2_nsec(value: Any, what: str) -> int:
    """Integer nanoseconds of an rclpy Time/Duration or a builtin_interfaces Time/Duration."""
    if hasattr(value, "sec") and hasattr(value, "nanosec"):
        return int(value.sec) * NS_PER_S + int(value.nanosec)
    if hasattr(value, "nanoseconds"):
        return int(value.nanoseconds)
    raise TypeError(
        f"{what}: time must have sec and nanosec, or nanoseconds; pass an rclpy.time.Time "
        "(rclpy.time.Time() for the latest transform), an rclpy.duration.Duration or a "
        f"builtin_interfaces Time, got {value!r}"
    )


ROS1 = Dialect(
    transform_type="geometry_msgs/TransformStamped",
    to_nsec=ros1_nsec,
    stamp=Time.from_nsec,
    time=Time.from_nsec,
    duration=Duration.from_nsec,
    timeout_example="rospy.Duration(1.0)",
)


def ros2(time: Callable[[int], Any], duration: Callable[[int], Any]) -> Dialect:
    """The ROS 2 dialect; rclpy's Time and Duration constructors come from the caller (the
    sandbox's rclpy lives on a ROS 2 node's path, not in this package)."""
    from sandbox.msgs import get_message_class

    stamp_class = get_message_class("builtin_interfaces/msg/Time")

    def stamp(ns: int) -> Any:
        seconds, nanoseconds = divmod(ns, NS_PER_S)
        return stamp_class(sec=seconds, nanosec=nanoseconds)

    return Dialect(
        transform_type="geometry_msgs/msg/TransformStamped",
        to_nsec=ros2_nsec,
        stamp=stamp,
        time=time,
        duration=duration,
        timeout_example="timeout=rclpy.duration.Duration(seconds=1.0)",
    )
