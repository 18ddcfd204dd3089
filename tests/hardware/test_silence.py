"""The sensor-silence watchdog's bounds and sentences (server/hardware/silence.py)."""

from __future__ import annotations

import pytest

from server.hardware.silence import SILENCE_LIMITS, SensorSilenceWatchdog


@pytest.mark.parametrize(
    ("rate_hz", "bound_s"),
    [(20.0, 0.3), (10.0, 0.5), (2.380952380952381, 2.1), (100.0, 0.3), (None, 2.5)],
)
def test_the_bound_is_five_periods_and_at_least_300_ms(rate_hz, bound_s):
    assert SILENCE_LIMITS.bound_s(rate_hz) == pytest.approx(bound_s)


def test_a_topic_silent_past_its_bound_is_named_with_the_time():
    watchdog = SensorSilenceWatchdog({"Distance": 20.0, "Light": 10.0}, start_s=100.0)
    for tick in range(10):
        watchdog.heard("Distance", 100.0 + 0.05 * tick)
        watchdog.heard("Light", 100.0 + 0.05 * tick)
    last_s = 100.45
    assert watchdog.check(last_s + 0.3) is None  # at the bound, not past it
    silence = watchdog.check(last_s + 0.31)
    assert silence is not None and silence.topic == "Distance"
    assert silence.sentence == "robot stopped sending Distance for 0.3 s"
    watchdog.heard("Distance", last_s + 0.31)
    assert watchdog.check(last_s + 0.5) is None  # Light's bound is 0.5 s
    assert watchdog.check(last_s + 0.52).sentence == "robot stopped sending Light for 0.5 s"


def test_a_topic_never_sent_trips_from_the_start_and_unwatched_ones_are_ignored():
    watchdog = SensorSilenceWatchdog({"odom": 20.0}, start_s=5.0)
    watchdog.heard("imu", 5.2)  # not watched: the base has no IMU
    assert watchdog.check(5.29) is None
    assert watchdog.check(5.31).sentence == "robot stopped sending odom for 0.3 s"


def test_a_topic_watched_from_its_first_message():
    watchdog = SensorSilenceWatchdog({}, start_s=0.0)
    assert watchdog.check(10.0) is None
    watchdog.watch("Distance", 20.0, since_s=10.0)
    assert watchdog.check(10.25) is None
    assert watchdog.check(10.4).topic == "Distance"


def test_silence_counts_from_the_start_of_the_run_at_the_earliest():
    watchdog = SensorSilenceWatchdog({}, start_s=50.0)
    watchdog.watch("Distance", 20.0, since_s=40.0)  # a reading from before the run
    assert watchdog.check(50.25) is None
    assert watchdog.check(50.35).topic == "Distance"


def test_when_several_go_silent_the_topic_the_nodes_read_is_named():
    """A robot that froze stops every topic at once; the one heard least recently (Light, here
    20 ms before Distance) trips first, but the node reads only Distance (issue 33)."""
    rates = {"Distance": 20.0, "Light": 20.0, "Line": 20.0}
    watchdog = SensorSilenceWatchdog(rates, start_s=0.0)
    watchdog.heard("Light", 1.00)
    watchdog.heard("Line", 1.01)
    watchdog.heard("Distance", 1.02)
    assert watchdog.check(1.301).topic == "Light"  # no word on what is read: as before
    silence = watchdog.check(1.301, is_read=lambda topic: topic == "Distance")
    assert silence.topic == "Distance"
    assert silence.sentence == "robot stopped sending Distance for 0.3 s"
    assert watchdog.check(1.29, is_read=lambda topic: topic == "Distance") is None


def test_a_read_topic_still_arriving_does_not_take_the_blame():
    watchdog = SensorSilenceWatchdog({"Distance": 20.0, "Light": 20.0}, start_s=0.0)
    watchdog.heard("Light", 1.0)
    watchdog.heard("Distance", 1.28)  # still arriving: heard 21 ms before the check
    silence = watchdog.check(1.301, is_read=lambda topic: topic == "Distance")
    assert silence.sentence == "robot stopped sending Light for 0.3 s"
