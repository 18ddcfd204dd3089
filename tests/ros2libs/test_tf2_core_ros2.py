"""The shared tf2 core (sandbox/tf2) in the ROS 2 dialect: ROS 2 TransformStamped messages in
(builtin_interfaces stamps), lookups at rclpy-style times (`nanoseconds`) or builtin ones (`sec`,
`nanosec`), ROS 2 messages out; the same answers as the ROS 1 dialect gives for the same tree;
tf2_geometry_msgs' transforms on ROS 2 messages."""

from __future__ import annotations

import math
from dataclasses import dataclass

import pytest
from scipy.spatial.transform import Rotation

from sandbox.msgs import Time as Ros1Time
from sandbox.msgs import get_message_class
from sandbox.tf2 import dialect, geometry
from sandbox.tf2.buffer_core import BufferCore
from sandbox.tf2.exceptions import ExtrapolationException, LookupException

NS = 1_000_000_000
Stamp = get_message_class("builtin_interfaces/msg/Time")
DurationMsg = get_message_class("builtin_interfaces/msg/Duration")
TransformStamped2 = get_message_class("geometry_msgs/msg/TransformStamped")
TransformStamped1 = get_message_class("geometry_msgs/TransformStamped")


@dataclass(frozen=True)
class RclpyLikeTime:
    """What tf2_py reads of an rclpy.time.Time: its `nanoseconds`."""

    nanoseconds: int


class Ros2Buffer(BufferCore):
    dialect = dialect.ros2(
        time=RclpyLikeTime,
        duration=lambda ns: DurationMsg(sec=ns // NS, nanosec=ns % NS),
    )


def fill(message_class, stamp, parent, child, t, x=0.0, yaw=0.0):
    message = message_class()
    message.header.frame_id, message.child_frame_id = parent, child
    message.header.stamp = stamp(t)
    message.transform.translation.x = x
    r = message.transform.rotation
    r.x, r.y, r.z, r.w = (float(v) for v in Rotation.from_euler("z", yaw).as_quat())
    return message


def ros2_stamp(t: float):
    ns = round(t * NS)
    return Stamp(sec=ns // NS, nanosec=ns % NS)


def build(buffer, message_class, stamp) -> None:
    for step in range(1, 6):
        buffer.set_transform(fill(message_class, stamp, "map", "odom", step, x=1.0), "test")
        buffer.set_transform(
            fill(message_class, stamp, "odom", "base_link", step, x=0.5 * step, yaw=0.2 * step),
            "test",
        )


def test_the_ros2_dialect_gives_the_ros1_answers_in_ros2_messages() -> None:
    ros2, ros1 = Ros2Buffer(), BufferCore()
    build(ros2, TransformStamped2, ros2_stamp)
    build(ros1, TransformStamped1, Ros1Time.from_sec)
    for t in (0.0, 1.0, 2.25, 5.0):
        ours = ros2.lookup_transform_core("map", "base_link", RclpyLikeTime(round(t * NS)))
        theirs = ros1.lookup_transform_core("map", "base_link", Ros1Time.from_sec(t))
        assert ours._type == "geometry_msgs/msg/TransformStamped"
        assert ours.header.frame_id == "map" and ours.child_frame_id == "base_link"
        expected_ns = theirs.header.stamp.to_nsec()
        assert ours.header.stamp.sec * NS + ours.header.stamp.nanosec == expected_ns
        a, b = ours.transform, theirs.transform
        assert (a.translation.x, a.translation.y) == pytest.approx(
            (b.translation.x, b.translation.y)
        )
        assert (a.rotation.z, a.rotation.w) == pytest.approx((b.rotation.z, b.rotation.w))
    at = ros2.lookup_transform_core("map", "base_link", ros2_stamp(2.5))  # a builtin Time works
    assert at.transform.translation.x == pytest.approx(1.0 + 1.25)


def test_times_cache_and_errors_in_ros2_words() -> None:
    buffer = Ros2Buffer(cache_time=DurationMsg(sec=2))
    build(buffer, TransformStamped2, ros2_stamp)
    assert buffer.get_latest_common_time("map", "base_link") == RclpyLikeTime(5 * NS)
    assert buffer.cache_time == DurationMsg(sec=2)
    with pytest.raises(ExtrapolationException, match="into the past"):
        buffer.lookup_transform_core("map", "base_link", RclpyLikeTime(1 * NS))
    empty = Ros2Buffer()
    with pytest.raises(LookupException, match=r"timeout=rclpy\.duration\.Duration"):
        empty.lookup_transform_core("map", "base_link", RclpyLikeTime(0))
    with pytest.raises(TypeError, match="time must have sec and nanosec, or nanoseconds"):
        buffer.lookup_transform_core("map", "base_link", 0.0)


def test_geometry_transforms_take_ros2_messages() -> None:
    transform = fill(TransformStamped2, ros2_stamp, "map", "base_link", 3.0, x=2.0, yaw=math.pi / 2)
    point = get_message_class("geometry_msgs/msg/PointStamped")()
    point.header.frame_id = "base_link"
    point.point.x = 1.0
    moved = geometry.do_transform_point(point, transform)
    assert moved._type == "geometry_msgs/msg/PointStamped" and moved.header.frame_id == "map"
    assert (moved.point.x, moved.point.y) == pytest.approx((2.0, 1.0))
    pose = get_message_class("geometry_msgs/msg/Pose")()
    pose.orientation.w = 1.0
    bare = geometry.do_transform_pose(pose, transform)  # ROS 2: a Pose in, a Pose out
    assert bare._type == "geometry_msgs/msg/Pose"
    assert (bare.position.x, bare.orientation.z) == pytest.approx((2.0, math.sqrt(0.5)))
    with pytest.raises(TypeError, match="TransformStamped"):
        geometry.do_transform_point(point, pose)


def test_a_traceback_names_tf2s_exceptions_as_tf2_does():
    # tf2_py defines them in its C module `tf2`: students see `tf2.LookupException`, not ours.
    import traceback

    try:
        raise LookupException('"base_foot" passed to lookupTransform does not exist')
    except LookupException as error:
        line = traceback.format_exception_only(error)[-1]
    assert line.startswith("tf2.LookupException: "), line
    assert ExtrapolationException.__module__ == "tf2"
