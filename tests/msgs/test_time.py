"""Tests for sandbox.msgs._time: canonical form, conversions, ordering and arithmetic."""

import pytest

from sandbox.msgs import Duration, Time


def test_nsecs_overflow_is_carried_into_secs() -> None:
    stamp = Time(1, 2_500_000_000)
    assert (stamp.secs, stamp.nsecs) == (3, 500_000_000)


def test_negative_duration_keeps_nsecs_non_negative() -> None:
    span = Duration(0, -1)
    assert (span.secs, span.nsecs) == (-1, 999_999_999)
    assert span.to_nsec() == -1


def test_time_cannot_be_negative() -> None:
    with pytest.raises(ValueError, match="Duration"):
        Time(-1, 0)


def test_from_sec_and_to_sec_round_trip() -> None:
    stamp = Time.from_sec(12.25)
    assert (stamp.secs, stamp.nsecs) == (12, 250_000_000)
    assert stamp.to_sec() == 12.25
    assert Duration.from_sec(-0.5).to_sec() == -0.5


def test_float_seconds_constructor_like_rospy() -> None:
    assert Time(1.5) == Time(1, 500_000_000)
    with pytest.raises(ValueError):
        Time(1.5, 3)


def test_ordering_and_equality() -> None:
    assert Time(1, 5) < Time(2, 0) <= Time(2, 0) < Time(2, 1)
    assert Time(3) > Time(2, 999_999_999)
    assert Time(1, 0) == Time(0, 1_000_000_000)
    assert Time(1) != Duration(1)
    assert hash(Time(1, 2)) == hash(Time(1, 2))


def test_time_plus_duration_and_time_minus_time() -> None:
    assert Time(1, 900_000_000) + Duration(0, 200_000_000) == Time(2, 100_000_000)
    assert Duration(1) + Time(1) == Time(2)
    assert Time(5) - Time(7, 500) == Duration(-2, -500)
    assert Time(5) - Duration(1) == Time(4)
    assert isinstance(Time(5) - Time(1), Duration)


def test_time_plus_time_is_rejected() -> None:
    with pytest.raises(TypeError):
        Time(1) + Time(2)  # type: ignore[operator]


def test_duration_arithmetic() -> None:
    assert Duration(2) * 1.5 == Duration(3)
    assert 2 * Duration(0, 3) == Duration(0, 6)
    assert Duration(3) / 2 == Duration(1, 500_000_000)
    assert Duration(3) / Duration(1, 500_000_000) == 2.0
    assert -Duration(1) == Duration(-1)
    assert abs(Duration(-1, 5)) == Duration(0, 999_999_995)


def test_truthiness_and_repr() -> None:
    assert not Time()
    assert Duration(0, 1)
    assert repr(Time(1, 2)) == "Time(secs=1, nsecs=2)"
