"""server.hardware.create.topics: frames in, the turtlebot's odom and bumper out, with the
times passed in (no port, no thread)."""

from __future__ import annotations

import math

import pytest

from sandbox.msgs import get_message_class
from server.hardware.create import kinematics, oi, topics

PERIOD_S = oi.STREAM_PERIOD_S
COUNTS_PER_FRAME = 7  # [counts] ~3.1 mm in 15 ms: ~0.207 m/s
SPEED_M_S = COUNTS_PER_FRAME * kinematics.METERS_PER_COUNT / PERIOD_S


def frame(left: int, right: int, bumps: int = 0, mode: int = 2) -> dict[int, int]:
    return {7: bumps, 35: mode, 43: left % 65536, 44: right % 65536}


def straight(count: int, start: int = 0) -> list[dict[int, int]]:
    return [frame(start + i * COUNTS_PER_FRAME, start + i * COUNTS_PER_FRAME) for i in range(count)]


def by_topic(pairs, topic):
    return [message for name, message in pairs if name == topic]


def test_topic_names_and_types_are_the_simulated_turtlebots():
    from server.sim.robots.turtlebot import TurtleBot

    robot = TurtleBot()
    sensors = robot.build_sensors()
    assert topics.TOPIC_CMD_VEL in robot.commands
    out = topics.CreateTopics().on_frames([frame(0, 0)], now_s=0.0, stamp_s=12.5)
    assert [name for name, _ in out] == [topics.TOPIC_ODOM, topics.TOPIC_BUMPER]
    for name, message in out:
        assert type(message) is sensors[name].msg_type
    odom = by_topic(out, "odom")[0]
    assert type(odom) is get_message_class("nav_msgs/Odometry")
    assert odom.header.stamp.to_sec() == 12.5
    assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_link")
    assert odom.pose.pose.orientation.w == 1.0


def test_publishes_at_the_rate_and_a_bump_at_once():
    state = topics.CreateTopics(publish_rate_hz=20.0)
    out = state.on_frames([frame(0, 0)], 0.0, 0.0)
    assert len(by_topic(out, "odom")) == 1
    assert state.on_frames([frame(0, 0)], 0.015, 0.015) == []  # not due, nothing changed
    out = state.on_frames([frame(0, 0, bumps=oi.BUMP_LEFT_BIT)], 0.030, 0.030)
    assert [m.data for m in by_topic(out, "bumper")] == [[1, 0]]
    assert by_topic(out, "odom") == []
    out = state.on_frames([frame(0, 0, bumps=oi.BUMP_LEFT_BIT | oi.BUMP_RIGHT_BIT)], 0.05, 0.05)
    assert [m.data for m in by_topic(out, "bumper")] == [[1, 1]]
    assert len(by_topic(out, "odom")) == 1


def test_wheel_drop_bits_are_not_bumps():
    state = topics.CreateTopics()
    out = state.on_frames([frame(0, 0, bumps=oi.WHEEL_DROP_LEFT_BIT)], 0.0, 0.0)
    assert by_topic(out, "bumper")[0].data == [0, 0]
    assert state.wheel_dropped


def test_twist_counts_15_ms_per_frame_when_frames_arrive_in_bunches():
    state = topics.CreateTopics(publish_rate_hz=20.0)
    frames = straight(41)
    state.on_frames(frames[:1], 0.0, 0.0)
    speeds = []
    # Delivered five at a time, at uneven host times (40-110 ms apart) for 75 ms of motion each.
    for index, host_s in zip(
        range(1, 40, 5), (0.04, 0.15, 0.21, 0.31, 0.37, 0.47, 0.53, 0.63), strict=True
    ):
        out = state.on_frames(frames[index : index + 5], host_s, host_s)
        speeds += [m.twist.twist.linear.x for m in by_topic(out, "odom")]
    assert len(speeds) == 7  # 40 ms after the first publish is not yet due
    assert speeds == pytest.approx([SPEED_M_S] * 7, rel=1e-9)


def test_twist_uses_host_time_when_frames_were_lost():
    state = topics.CreateTopics(publish_rate_hz=20.0)
    state.on_frames([frame(0, 0)], 0.0, 0.0)
    # 20 frames' worth of motion (300 ms) arrives in one frame 300 ms later: 19 were lost.
    out = state.on_frames([frame(20 * COUNTS_PER_FRAME, 20 * COUNTS_PER_FRAME)], 0.3, 0.3)
    assert by_topic(out, "odom")[0].twist.twist.linear.x == pytest.approx(SPEED_M_S)


def test_a_spin_reports_yaw_and_yaw_rate():
    state = topics.CreateTopics(publish_rate_hz=1000.0)
    state.on_frames([frame(0, 0)], 0.0, 0.0)
    quarter = round(0.5 * kinematics.WHEEL_BASE_M * math.pi / 2 / kinematics.METERS_PER_COUNT)
    out = state.on_frames([frame(-quarter, quarter)], PERIOD_S, PERIOD_S)
    odom = by_topic(out, "odom")[0]
    yaw = 2.0 * math.atan2(odom.pose.pose.orientation.z, odom.pose.pose.orientation.w)
    assert yaw == pytest.approx(math.pi / 2, abs=0.005)
    assert odom.twist.twist.angular.z == pytest.approx(math.pi / 2 / PERIOD_S, rel=0.005)
    assert odom.twist.twist.linear.x == pytest.approx(0.0, abs=1e-9)


def test_a_bad_rate_is_refused():
    with pytest.raises(ValueError, match="publish_rate_hz must be > 0"):
        topics.CreateTopics(publish_rate_hz=0.0)


def test_twenty_hz_on_average_from_15_ms_frames():
    state = topics.CreateTopics(publish_rate_hz=20.0)
    frames = straight(200)  # 3 s
    published = sum(
        len(by_topic(state.on_frames([f], i * PERIOD_S, i * PERIOD_S), "odom"))
        for i, f in enumerate(frames)
    )
    assert published == pytest.approx(200 * PERIOD_S * 20.0, abs=1)
