"""A robot's health as the instructor's robot list shows it: one of four states, when it was
last heard, and its problems, each from what the link knows now (not a snapshot taken when the
robot connected, which once kept "connected with problems" after a reconnection that worked).

- connected: the link is up, in sync (rosserial: the robot's time requests are answered; a
  Create: its sensor stream flows) and the robot was heard within `STALE_AFTER_S`;
- syncing: the link is up but the handshake is not (yet, or again) complete: topics requested,
  no time request answered since;
- stale: the link is up and in sync, but the robot has been silent for `STALE_AFTER_S`: a
  frozen firmware or a stuck WiFi link, before the host's timeouts close the connection;
- disconnected: no link (the sentence is "not connected", which the pages compare with).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from enum import StrEnum

# [s] silent this long, the robot is stale. Longer than ros_lib's 2.5 s time-request period, so
# a configured robot that publishes nothing is not stale; far shorter than the host's 15 s sync
# and 30 s idle timeouts, so the instructor sees a frozen robot long before it is disconnected.
STALE_AFTER_S = 3.0
NOT_CONNECTED = "not connected"  # what web/src compares `connection` with


class HealthState(StrEnum):
    CONNECTED = "connected"
    SYNCING = "syncing"
    STALE = "stale"
    DISCONNECTED = "disconnected"


@dataclass(frozen=True, slots=True)
class LinkHealth:
    """What a link knows of itself: in sync or not, and when it last heard the robot."""

    synced: bool
    last_heard_s: float | None  # [s] monotonic


@dataclass(frozen=True, slots=True)
class RobotHealth:
    state: HealthState
    last_heard_s_ago: float | None  # [s]
    last_heard_at: float | None  # [s] since the epoch
    problems: tuple[str, ...]

    @property
    def sentence(self) -> str:
        """The `connection` text of the robot list."""
        problems = "; ".join(self.problems)
        match self.state:
            case HealthState.DISCONNECTED:
                return NOT_CONNECTED
            case HealthState.SYNCING:
                text = "syncing: topics requested, waiting for the robot's time request"
            case HealthState.STALE:
                text = f"stale: connected, but nothing heard for {self.last_heard_s_ago:.0f} s"
            case _:
                text = "connected"
        if problems:
            return f"{text} with problems: {problems}" if text == "connected" else (
                f"{text}; problems: {problems}"
            )  # fmt: skip
        return text

    def as_dict(self) -> dict:
        return {
            "state": str(self.state),
            "last_heard_s_ago": (
                None if self.last_heard_s_ago is None else round(self.last_heard_s_ago, 2)
            ),
            "last_heard_at": self.last_heard_at,
            "problems": list(self.problems),
        }


def assess(
    link: LinkHealth | None,
    problems: list[str] | tuple[str, ...] = (),
    now_s: float | None = None,
    wall_now_s: float | None = None,
) -> RobotHealth:
    """The health of a robot whose link reports `link` (None: no link) at monotonic `now_s`."""
    now_s = time.monotonic() if now_s is None else now_s
    wall_now_s = time.time() if wall_now_s is None else wall_now_s
    if link is None:
        return RobotHealth(HealthState.DISCONNECTED, None, None, tuple(problems))
    ago = None if link.last_heard_s is None else max(0.0, now_s - link.last_heard_s)
    at = None if ago is None else round(wall_now_s - ago, 3)
    if not link.synced:
        state = HealthState.SYNCING
    elif ago is None or ago > STALE_AFTER_S:
        state = HealthState.STALE
    else:
        state = HealthState.CONNECTED
    return RobotHealth(state, ago, at, tuple(problems))
