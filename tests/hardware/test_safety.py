"""The safety layer between a student's command and a real robot."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from server.hardware.safety import MotionLimits, Velocity, VelocityLimiter, Watchdog

LIMITS = MotionLimits(
    max_linear_m_s=0.3, max_angular_rad_s=2.0, max_linear_accel_m_s2=1.0,
    max_angular_accel_rad_s2=4.0,
)  # fmt: skip


def test_commands_are_clamped_to_the_robots_speeds():
    limiter = VelocityLimiter(LIMITS)
    assert limiter.apply(Velocity(5.0, -9.0), 0.0) == Velocity(0.0, 0.0)  # from rest: ramped
    assert limiter.apply(Velocity(5.0, -9.0), 10.0) == Velocity(0.3, -2.0)
    assert limiter.clamped == 2


def test_a_step_to_full_speed_is_ramped_by_the_acceleration_limit():
    limiter = VelocityLimiter(LIMITS)
    limiter.apply(Velocity(0.0, 0.0), 0.0)
    assert limiter.apply(Velocity(0.3, 0.0), 0.1).linear_m_s == pytest.approx(0.1)  # 1 m/s^2
    assert limiter.apply(Velocity(0.3, 0.0), 0.2).linear_m_s == pytest.approx(0.2)
    assert limiter.apply(Velocity(-0.3, 0.0), 0.25).linear_m_s == pytest.approx(0.15)


def test_the_limiter_says_which_limits_changed_a_command():
    limiter = VelocityLimiter(LIMITS)
    limiter.apply(Velocity(0.0, 0.0), 0.0)
    assert limiter.limited_by == ()
    limiter.apply(Velocity(5.0, 0.0), 0.1)  # too fast, and a step from rest
    assert limiter.limited_by == ("max_linear_m_s", "max_linear_accel_m_s2")
    limiter.apply(Velocity(0.3, 1.0), 10.0)  # reachable in 9.9 s: as asked
    assert limiter.limited_by == ()
    limiter.apply(Velocity(math.nan, 1.0), 10.1)
    assert limiter.limited_by == ("not_finite", "max_linear_accel_m_s2")


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_nan_and_inf_stop_the_robot(bad):
    assert VelocityLimiter(LIMITS).apply(Velocity(bad, bad), 0.0) == Velocity(0.0, 0.0)


@given(
    st.lists(
        st.tuples(st.floats(allow_nan=True), st.floats(allow_nan=True), st.floats(0, 1)),
        max_size=50,
    )
)
def test_whatever_a_student_sends_stays_within_the_limits(commands):
    limiter, now = VelocityLimiter(LIMITS), 0.0
    previous = Velocity()
    for linear, angular, dt in commands:
        now += dt
        sent = limiter.apply(Velocity(linear, angular), now)
        assert abs(sent.linear_m_s) <= LIMITS.max_linear_m_s
        assert abs(sent.angular_rad_s) <= LIMITS.max_angular_rad_s
        if dt > 0:
            assert abs(sent.linear_m_s - previous.linear_m_s) <= 1.0 * dt + 1e-9
        previous = sent


def test_the_watchdog_stops_a_silent_controller_once_per_silence():
    watchdog = Watchdog(0.5)
    assert watchdog.expired(0.0)  # nothing commanded yet: zero
    watchdog.feed(1.0)
    assert not watchdog.expired(1.4)
    assert watchdog.expired(1.6) and watchdog.expired(2.0)
    assert watchdog.trips == 1
    watchdog.feed(2.1)
    assert not watchdog.expired(2.2)


@pytest.mark.parametrize("value", [0, -1, math.nan, math.inf])
def test_limits_must_be_positive_numbers(value):
    with pytest.raises(ValueError, match="positive number"):
        MotionLimits(value, 1.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="positive number"):
        Watchdog(value)
