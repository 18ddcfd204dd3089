"""server.hardware.create.kinematics: wheel speeds from a Twist, odometry from encoder counts
(with the 16-bit counters rolling over)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from server.hardware.create import kinematics as k

MM_PER_COUNT = math.pi * 72.0 / 508.8  # [mm/count] OI spec, packets 43/44


def counts(meters: float) -> int:
    return round(meters * 1000.0 / MM_PER_COUNT)


def test_constants_are_the_oi_specs():
    assert k.WHEEL_BASE_M == 0.235
    assert k.WHEEL_DIAMETER_M == 0.072
    assert k.COUNTS_PER_REV == 508.8
    assert pytest.approx(MM_PER_COUNT) == 1000.0 * k.METERS_PER_COUNT


def test_straight_and_spin_wheel_speeds():
    assert k.twist_to_wheel_speeds(0.2, 0.0) == k.WheelSpeeds(0.2, 0.2)
    spin = k.twist_to_wheel_speeds(0.0, 1.0)
    assert spin.left_m_s == pytest.approx(-0.1175)
    assert spin.right_m_s == pytest.approx(0.1175)  # right faster: counter-clockwise, REP 103


def test_a_command_past_the_wheel_limit_keeps_its_curve():
    fast = k.twist_to_wheel_speeds(1.0, 2.0)
    assert max(abs(fast.left_m_s), abs(fast.right_m_s)) == pytest.approx(0.5)
    # same ratio of omega to v as asked: (right - left) / track / ((left + right) / 2) = 2
    ratio = (
        (fast.right_m_s - fast.left_m_s) / k.WHEEL_BASE_M / (0.5 * (fast.left_m_s + fast.right_m_s))
    )
    assert ratio == pytest.approx(2.0)


def test_non_finite_commands_are_refused():
    with pytest.raises(ValueError, match="finite"):
        k.twist_to_wheel_speeds(float("nan"), 0.0)
    with pytest.raises(ValueError, match="finite"):
        k.twist_to_wheel_speeds(0.0, float("inf"))


@pytest.mark.parametrize(
    ("previous", "current", "delta"),
    [(0, 10, 10), (10, 0, -10), (65530, 4, 10), (4, 65530, -10), (65535, 0, 1), (0, 65535, -1)],
)
def test_encoder_delta_wraps_at_16_bits(previous, current, delta):
    assert k.encoder_delta(previous, current) == delta


@given(start=st.integers(0, 65535), step=st.integers(-32768, 32767))
def test_encoder_delta_inverts_a_wrapped_step(start, step):
    assert k.encoder_delta(start, (start + step) % 65536) == step


def test_first_sample_is_the_reference():
    odometry = k.EncoderOdometry()
    assert not odometry.started
    assert odometry.update(40000, 12345).distance_m == 0.0
    assert odometry.started
    assert odometry.pose == k.Pose2D()


def test_straight_line_through_the_wraparound():
    odometry = k.EncoderOdometry()
    start = 65000
    odometry.update(start, start)
    per_step = counts(0.003)  # 3 mm per 15 ms frame = 0.2 m/s
    total = 0
    for _ in range(100):  # 0.3 m: ~675 counts, past 65535
        total += per_step
        odometry.update((start + total) % 65536, (start + total) % 65536)
    assert odometry.pose.x_m == pytest.approx(total * MM_PER_COUNT / 1000.0)
    assert start + total > 65535  # the counters did roll over
    assert odometry.pose.x_m == pytest.approx(0.3, abs=0.015)  # 3 mm rounds to 7 counts
    assert odometry.pose.y_m == pytest.approx(0.0, abs=1e-12)
    assert odometry.pose.yaw_rad == pytest.approx(0.0, abs=1e-12)


def test_backwards_through_the_wraparound():
    odometry = k.EncoderOdometry()
    odometry.update(100, 100)
    odometry.update((100 - 500) % 65536, (100 - 500) % 65536)
    assert odometry.pose.x_m == pytest.approx(-500 * MM_PER_COUNT / 1000.0)


def test_spin_in_place_quarter_turn():
    odometry = k.EncoderOdometry()
    odometry.update(0, 0)
    arc_m = 0.5 * k.WHEEL_BASE_M * (math.pi / 2)
    steps = 50
    for i in range(1, steps + 1):
        wheel = arc_m * i / steps
        odometry.update(-counts(wheel) % 65536, counts(wheel))
    assert odometry.pose.yaw_rad == pytest.approx(math.pi / 2, abs=0.005)
    assert math.hypot(odometry.pose.x_m, odometry.pose.y_m) < 1e-9


def test_a_full_circle_comes_back_to_the_start():
    odometry = k.EncoderOdometry()
    odometry.update(0, 0)
    radius_m = 0.5
    left_total = right_total = 0.0
    steps = 400
    for _ in range(steps):
        turn = 2 * math.pi / steps
        left_total += (radius_m - 0.5 * k.WHEEL_BASE_M) * turn
        right_total += (radius_m + 0.5 * k.WHEEL_BASE_M) * turn
        odometry.update(counts(left_total) % 65536, counts(right_total) % 65536)
    assert odometry.pose.x_m == pytest.approx(0.0, abs=0.01)
    assert odometry.pose.y_m == pytest.approx(0.0, abs=0.01)
    assert odometry.pose.yaw_rad == pytest.approx(0.0, abs=0.01)


def test_an_arc_ends_where_geometry_says():
    # A quarter circle of radius 1 m to the left, in one sample: exact arc integration.
    pose = k.advance_pose(k.Pose2D(), distance_m=math.pi / 2, yaw_change_rad=math.pi / 2)
    assert (pose.x_m, pose.y_m, pose.yaw_rad) == pytest.approx((1.0, 1.0, math.pi / 2))


def test_yaw_stays_wrapped():
    pose = k.advance_pose(k.Pose2D(yaw_rad=3.0), distance_m=0.0, yaw_change_rad=0.5)
    assert pose.yaw_rad == pytest.approx(3.5 - 2 * math.pi)
