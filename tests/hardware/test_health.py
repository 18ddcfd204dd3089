"""Robot health (server/hardware/health.py) and the hub's view of it: four states, the last
time heard, and problems read from the link now, so a clean handshake clears them."""

from __future__ import annotations

import time
from types import SimpleNamespace

from server.hardware.health import STALE_AFTER_S, HealthState, LinkHealth, assess
from server.service.hardware import HardwareHub

NOW = 1000.0  # [s] monotonic
WALL = 1_800_000_000.0  # [s] epoch


def test_the_four_states_and_their_sentences():
    gone = assess(None, now_s=NOW, wall_now_s=WALL)
    assert gone.state is HealthState.DISCONNECTED and gone.sentence == "not connected"
    syncing = assess(LinkHealth(False, NOW - 0.1), now_s=NOW, wall_now_s=WALL)
    assert syncing.state is HealthState.SYNCING
    assert syncing.sentence.startswith("syncing: topics requested")
    fresh = assess(LinkHealth(True, NOW - 0.05), now_s=NOW, wall_now_s=WALL)
    assert fresh.state is HealthState.CONNECTED and fresh.sentence == "connected"
    assert fresh.as_dict() == {
        "state": "connected",
        "last_heard_s_ago": 0.05,
        "last_heard_at": WALL - 0.05,
        "problems": [],
    }
    stale = assess(LinkHealth(True, NOW - STALE_AFTER_S - 1.2), now_s=NOW, wall_now_s=WALL)
    assert stale.state is HealthState.STALE
    assert stale.sentence == "stale: connected, but nothing heard for 4 s"
    troubled = assess(LinkHealth(True, NOW), ["topic 'x' refused"], now_s=NOW, wall_now_s=WALL)
    assert troubled.sentence == "connected with problems: topic 'x' refused"


class FakeLink:
    def __init__(self) -> None:
        self.connected = True
        self.problems = ["Tried to publish before configured, topic id 125"]
        self.synced = True

    def health(self) -> LinkHealth:
        return LinkHealth(self.synced, time.monotonic())


def test_the_hub_reads_problems_from_the_link_now():
    settings = SimpleNamespace(rosserial_port=-1, hardware_slot_s=300.0,
                               hardware_start_within_s=60.0)  # fmt: skip
    hub = HardwareHub(store=None, settings=settings)
    assert hub.connection_state("crowbot-1") == "not connected"
    link = FakeLink()
    hub._links["crowbot-1"] = link
    assert hub.connection_state("crowbot-1").startswith("connected with problems: Tried")
    assert hub.problems() == {"crowbot-1": link.problems}
    link.problems = []  # the handshake explained it (RosserialSession forgets it)
    assert hub.connection_state("crowbot-1") == "connected"
    assert hub.health("crowbot-1").state is HealthState.CONNECTED
    assert hub.problems() == {}
    link.synced = False
    assert hub.health("crowbot-1").state is HealthState.SYNCING
    link.connected = False
    assert hub.health("crowbot-1").state is HealthState.DISCONNECTED
