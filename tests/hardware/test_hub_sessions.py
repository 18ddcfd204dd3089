"""The hub's sessions (issue 33, finding 14): a second connection from an idle robot's address
replaces its session, and the replaced connection is stopped at once; nothing it still sends
reaches the new link (the runs read that), and its close does not end the new link."""

from __future__ import annotations

import contextlib
from types import SimpleNamespace

from sandbox.msgs.std_msgs import Int32
from server.service import hardware as hub_module
from server.service.hardware import HardwareHub

ADDRESS = "10.42.0.7"


class FakeConnection:
    """A RobotConnection as the hub uses it: an id, a peer, topics, and stop()."""

    def __init__(self, robot_id: str) -> None:
        self.id = robot_id
        self.peer = (ADDRESS, 4000)
        self.topics = {}
        self.problems: list[str] = []
        self.connected = True
        self.stops = 0
        self.close_reason: str | None = None

    def stop(self) -> None:
        self.stops += 1


def make_hub(monkeypatch) -> HardwareHub:
    entry = SimpleNamespace(name="crowbot-1", kind="crowbot")
    monkeypatch.setattr(hub_module.inventory, "by_address", lambda db, transport, host: entry)
    store = SimpleNamespace(session=contextlib.nullcontext)
    settings = SimpleNamespace(rosserial_port=-1, hardware_slot_s=60.0,
                               hardware_start_within_s=60.0)  # fmt: skip
    return HardwareHub(store=store, settings=settings)


def test_a_replaced_connection_is_stopped_and_feeds_no_run(monkeypatch):
    hub = make_hub(monkeypatch)
    old, new = FakeConnection("robot-1"), FakeConnection("robot-2")
    hub.on_robot_connected(old)
    first = hub.link("crowbot-1")
    assert first is not None and first.connection is old
    hub.on_robot_connected(new)
    link = hub.link("crowbot-1")
    assert link is not None and link.connection is new
    assert old.stops == 1 and new.stops == 0  # stopped at once (at rest, tx-stop, closed)
    assert not first.connected and "replaced this connection" in first.lost_reason
    hub.on_message(old, "Distance", Int32(433))  # what the old one still had on the wire
    hub.on_message(new, "Distance", Int32(253))
    assert [message.data for _, message, _ in link.take_received()] == [253]
    hub.on_robot_disconnected(old, "stopped by RoboDojo (tx stop sent)")
    assert link.connected and hub.link("crowbot-1") is link  # its close ends only itself


def test_a_dropped_link_says_so(monkeypatch):
    hub = make_hub(monkeypatch)
    robot = FakeConnection("robot-1")
    hub.on_robot_connected(robot)
    link = hub.link("crowbot-1")
    hub.on_robot_disconnected(robot, "the robot closed the connection")
    assert not link.connected
    assert link.lost_reason == "lost the link to the robot: the robot closed the connection"
