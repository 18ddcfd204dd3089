"""`CreateLink`: a `CreateDriver` as a `RobotLink` (server/hardware/backend.py), so a Run can
drive a real Create/Roomba base through `HardwareRobot("turtlebot", link, limits)` as it drives
a rosserial CrowBot.

    link = CreateLink("/dev/ttyUSB0")
    link.open()                        # CreatePortError / CreateNoAnswerError, with a sentence
    robot = HardwareRobot("turtlebot", link, limits)
    ...
    link.close()                       # zero velocity, Passive, port released

The driver's reader thread pushes odom and bumper into a bounded inbox (latest values win when
no run is reading); `take_received()` hands them over with their monotonic receive times.
`connected` is true only while frames stream: a silent robot (0.5 s without a frame, see
driver.SILENCE_TIMEOUT_S) ends the run, since its odometry is frozen and nothing says whether
it still obeys.
"""

from __future__ import annotations

import time

from server.hardware.create.driver import CreateDriver, CreateState
from server.hardware.create.topics import TOPIC_BUMPER, TOPIC_CMD_VEL, TOPIC_ODOM
from server.hardware.health import LinkHealth
from server.hardware.inbox import Received, ReceivedInbox

INBOX_MAX = 1000  # messages waiting for a run: 25 s of odom + bumper at 20 Hz; older ones go


class CreateLink:
    """See module doc. Options other than `inbox_max` go to `CreateDriver`."""

    def __init__(
        self, port: str, baud: int | None = None, *, inbox_max: int = INBOX_MAX, **options
    ) -> None:
        if "on_message" in options:
            raise TypeError("CreateLink owns on_message; read messages with take_received()")
        if baud is not None:
            options["baud"] = baud
        self.driver = CreateDriver(port, on_message=self._push, **options)
        self._inbox = ReceivedInbox(inbox_max)
        self._heard_s: float | None = None  # [s] monotonic, the latest message

    def open(self) -> None:
        self.driver.open()

    def close(self) -> None:
        self.driver.close()

    @property
    def connected(self) -> bool:
        return self.driver.state is CreateState.STREAMING

    @property
    def lost_reason(self) -> str:
        if self.connected:
            return ""
        return self.driver.problem or f"the Create driver is {self.driver.state.value}"

    def health(self) -> LinkHealth:
        """In sync while frames stream (or only just stopped), and the last message's time."""
        state = self.driver.state
        return LinkHealth(state in (CreateState.STREAMING, CreateState.SILENT), self._heard_s)

    @property
    def problems(self) -> list[str]:
        problem = self.driver.problem
        return [problem] if problem else []

    @property
    def publishes(self) -> frozenset[str]:
        """The topics the driver publishes (watched for silence during a run)."""
        return frozenset({TOPIC_ODOM, TOPIC_BUMPER})

    def send(self, topic: str, message: object) -> None:
        if topic != TOPIC_CMD_VEL:
            raise ValueError(
                f"the Create base takes only {TOPIC_CMD_VEL!r} (geometry_msgs/Twist), not {topic!r}"
            )
        self.driver.command(message)

    def take_received(self) -> list[Received]:
        """(topic, message, monotonic receive time [s]) since the last call."""
        return self._inbox.take()

    def drain(self) -> None:
        """Forget what arrived before a run started."""
        self._inbox.clear()

    def _push(self, topic: str, message: object) -> None:
        now_s = time.monotonic()
        self._inbox.push(topic, message, now_s)
        self._heard_s = now_s
