"""The sensor-silence watchdog of a hardware run: a robot whose readings stop arriving ends the
run, since the student's controller would go on commanding on the last reading it got.

A robot can freeze without closing its connection (a stalled firmware, a WiFi link stuck in
retries): TCP stays up, the rosserial host only notices a lost time sync after 15 s, and a run
once went on to "finished: duration reached" 25 s after the last Distance. Here each sensor topic
the run depends on has a bound derived from its rate (`SILENCE_LIMITS`); when one is silent past
its bound the watchdog names it, and HardwareRobot sends zero velocity and ends the run
"failed: robot stopped sending Distance for 0.3 s".

A topic the link says the robot publishes is watched from the start of the run: a robot that
never sends one trips the watchdog as one that stopped. Pure: times are passed in, so the tests
drive them.

A robot that freezes stops all its topics at once, and the one heard least recently trips first:
a run whose node reads only Distance once ended "robot stopped sending Light". When a topic
trips, one the run's nodes read that is silent too (past `together_fraction` of its bound) is
named instead, since that is the silence the student's code saw (`check(now_s, is_read)`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class SilenceLimits:
    """How long a sensor topic may be silent; see `SILENCE_LIMITS` for the why of each value."""

    periods: float
    min_bound_s: float
    default_rate_hz: float
    together_fraction: float

    def bound_s(self, rate_hz: float | None) -> float:
        """[s] the longest silence allowed to a topic published at `rate_hz`."""
        rate = rate_hz if rate_hz is not None and rate_hz > 0 else self.default_rate_hz
        return max(self.periods / rate, self.min_bound_s)


SILENCE_LIMITS = SilenceLimits(
    # [periods] of the topic's rate: a WiFi link drops or delays a frame or two (a retry, a
    # beacon interval of ~100 ms); five in a row is a robot or a link that has stopped.
    periods=5.0,
    # [s] the floor: a 20 Hz topic's 5 periods (250 ms) are within one WiFi power-save wake-up
    # and a loaded bench host's scheduling jitter; 300 ms still stops a 0.128 m/s CrowBot within
    # 4 cm of where its last reading put it.
    min_bound_s=0.3,
    # [Hz] a topic whose model gives no rate (event topics): assume 2 Hz, i.e. a 2.5 s bound.
    default_rate_hz=2.0,
    # [fraction of a bound] when one topic trips, another silent for this share of its own
    # bound went silent with it: topics of one robot trip at most one period apart (50 ms at
    # 20 Hz, a sixth of the 300 ms bound), while a topic that is merely between two readings
    # has been silent for at most a period or two, well under half.
    together_fraction=0.5,
)


@dataclass(frozen=True, slots=True)
class Silence:
    """A watched topic went silent past its bound."""

    topic: str
    silent_s: float  # [s] since its last message (or the start of the run)
    bound_s: float  # [s] what it was allowed

    @property
    def sentence(self) -> str:
        return f"robot stopped sending {self.topic} for {self.silent_s:.1f} s"


class SensorSilenceWatchdog:
    """Per watched topic, the time of its last message; `check()` names the first silent one."""

    def __init__(
        self,
        rates_hz: Mapping[str, float | None],
        start_s: float,
        limits: SilenceLimits = SILENCE_LIMITS,
    ) -> None:
        self.limits = limits
        self.start_s = start_s  # [s] silence counts from here at the earliest (the run's start)
        self.bounds_s = {topic: limits.bound_s(rate) for topic, rate in rates_hz.items()}
        self._last_s = dict.fromkeys(self.bounds_s, start_s)

    @property
    def topics(self) -> tuple[str, ...]:
        return tuple(self.bounds_s)

    def watch(self, topic: str, rate_hz: float | None, since_s: float) -> None:
        """Watch one more topic, silent since `since_s` [s] (a link that does not say what it
        publishes has each topic watched from its first message)."""
        self.bounds_s[topic] = self.limits.bound_s(rate_hz)
        self._last_s[topic] = max(since_s, self.start_s)

    def heard(self, topic: str, at_s: float) -> None:
        """A message on `topic` arrived at `at_s` [s] (ignored for topics not watched)."""
        last = self._last_s.get(topic)
        if last is not None and at_s > last:
            self._last_s[topic] = at_s

    def check(self, now_s: float, is_read: Callable[[str], bool] | None = None) -> Silence | None:
        """The silence to report at `now_s` [s], or None while every topic is within its bound.
        Of the topics past their bound, the one silent longest past it; but if `is_read` (does
        a node of the run read this topic?) names topics that are silent too (past
        `together_fraction` of their bound), the longest silent of those instead."""
        silences = [
            Silence(topic, now_s - self._last_s[topic], bound_s)
            for topic, bound_s in self.bounds_s.items()
        ]
        tripped = [silence for silence in silences if silence.silent_s > silence.bound_s]
        if not tripped:
            return None
        if is_read is not None:
            together = self.limits.together_fraction
            read = [
                silence
                for silence in silences
                if silence.silent_s > together * silence.bound_s and is_read(silence.topic)
            ]
            if read:
                return max(read, key=_past_bound)
        return max(tripped, key=_past_bound)


def _past_bound(silence: Silence) -> float:
    """[s] how far a silence is past its bound (negative: within it)."""
    return silence.silent_s - silence.bound_s
