"""`RosserialLink`: a robot's rosserial connection as a `RobotLink` (server/hardware/backend.py),
so a Run drives a CrowBot running ros_lib through `HardwareRobot("crowbot", link, limits)` as it
drives a Create base through `CreateLink` (server/hardware/create/link.py).

    link = RosserialLink(connection, "crowbot-1")    # made by the hub when the robot connects
    link.push(topic, message)                         # the rosserial thread: what arrived
    link.take_received()                              # the run's loop: what arrived since

The rosserial thread hands each message to a bounded inbox (latest values win when no run is
reading). `connected` asks the connection itself, since its session closes before the hub hears
of it; `lost_reason` then says so too, so a run on a link that dropped ends naming the lost link
("failed: lost the link to the robot: the robot closed the connection"), whoever noticed first.
"""

from __future__ import annotations

import threading
import time
from collections import deque

from server.hardware.backend import RobotLost
from server.hardware.health import LinkHealth
from server.hardware.inbox import Received, ReceivedInbox
from server.hardware.rosserial.server import RobotConnection
from server.hardware.rosserial.session import RobotDisconnected, SessionState

INBOX_MAX = 1000  # messages waiting for a run: ~10 s of the CrowBot's topics; older ones go
LOG_LINES_KEPT = 200  # per robot, for the instructor


def link_lost(reason: str | None) -> str:
    """The sentence a run on a dropped link ends with; `reason` is the session's."""
    return f"lost the link to the robot: {reason or 'the connection closed'}"


class RosserialLink:
    """A rosserial connection as a `RobotLink` (server/hardware/backend.py)."""

    def __init__(self, connection: RobotConnection, name: str) -> None:
        self.connection = connection
        self.name = name
        self._lost_reason = ""  # set by lose(): the hub's word on why the link is gone
        self._inbox = ReceivedInbox(INBOX_MAX)
        self._lock = threading.Lock()  # the robot's log lines: rosserial thread -> run
        self.logs: deque[str] = deque(maxlen=LOG_LINES_KEPT)  # the instructor's view
        self._new_logs: deque[str] = deque(maxlen=LOG_LINES_KEPT)  # for the run on the robot

    @property
    def connected(self) -> bool:
        # The session closes before the hub hears of it: ask the connection itself.
        return not self._lost_reason and self.connection.connected

    @property
    def lost_reason(self) -> str:
        """Why the link is gone, as a sentence ("" while connected)."""
        if self._lost_reason:
            return self._lost_reason
        if not self.connection.connected:
            return link_lost(self.connection.close_reason)
        return ""

    def health(self) -> LinkHealth:
        """In sync (READY, its time requests answered) and when the robot was last heard."""
        connection = self.connection
        session = connection.session
        synced = self.connected and session.synced and session.state is SessionState.READY
        return LinkHealth(synced, connection.last_heard_s)

    @property
    def problems(self) -> list[str]:
        """The session's problems now (a clean handshake clears those it explains)."""
        return self.connection.problems

    @property
    def publishes(self) -> frozenset[str]:
        """The topics the robot advertised and RoboDojo accepted (watched for silence)."""
        return frozenset(self.connection.session.publishers)

    def send(self, topic: str, message: object) -> None:
        try:
            self.connection.send(topic, message)
        except RobotDisconnected:
            reason = self.lost_reason or link_lost(None)
            self.lose(reason)
            raise RobotLost(reason) from None

    @property
    def listened_until_s(self) -> float | None:
        """[s] monotonic: everything the robot sent before this is in the inbox (None: not yet
        known); the silence watchdog counts no further (server/hardware/backend.py)."""
        return self.connection.listened_until_s

    def take_received(self) -> list[Received]:
        return self._inbox.take()

    def drain(self) -> None:
        """Forget what arrived before a run started."""
        self._inbox.clear()

    def log(self, line: str) -> None:
        self.logs.append(line)
        self._new_logs.append(line)

    def take_logs(self) -> list[str]:
        with self._lock:
            taken = list(self._new_logs)
            self._new_logs.clear()
        return taken

    def push(self, topic: str, message: object) -> None:
        self._inbox.push(topic, message, time.monotonic())

    def lose(self, reason: str) -> None:
        """The link is gone for good (`reason`, a sentence); the first reason given stays."""
        if not self._lost_reason:
            self._lost_reason = reason or link_lost(None)
