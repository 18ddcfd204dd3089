"""A Run on a (test double of a) real robot: the simulated robot's topics, the safety layer
between the node and the wire, the watchdog, zero at every end, and a lost link ending the run.
The double is a link object as the protocol adapters present one; the wire itself is tested
with the firmware emulator (test_rosserial*) and the Create emulator (test_create*)."""

from __future__ import annotations

import threading
import time

import pytest
from mcap.reader import make_reader

from sandbox.msgs import get_message_class
from sandbox.msgs.geometry_msgs import Twist
from sandbox.msgs.std_msgs import Int32
from sandbox.protocol import Clock
from server.hardware.backend import HardwareRobot, RobotSilent
from server.hardware.safety import MotionLimits
from server.runs.run import Run
from server.runs.spec import NodeSpec, RunSpec, RunSpecError
from server.runs.state import RunState

LIMITS = MotionLimits(0.2, 2.0, 1.0, 8.0)
DRIVER = """\
RATE_HZ = 20
SUBSCRIBE = ["Distance"]


def step(obs):
    if obs.Distance is None:
        return None
    print("saw", obs.Distance.data)
    return {"Control": (5.0, 0.0)}  # far too fast: the limiter must clamp it
"""


class FakeCrowBot:
    """A connected CrowBot as the rosserial session would present it: publishes Distance at
    20 Hz from a thread, records what it is sent."""

    def __init__(self) -> None:
        self.connected = True
        self.lost_reason = ""
        self.sent: list[tuple[float, str, object]] = []
        self._received: list[tuple[str, object, float]] = []
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self.frozen = threading.Event()
        self._thread = threading.Thread(target=self._publish, daemon=True)
        self._thread.start()

    def _publish(self) -> None:
        while not self._stop.wait(0.05):
            if self.frozen.is_set():
                continue  # the firmware stalled: the socket stays open, nothing arrives
            with self._lock:
                self._received.append(("Distance", Int32(data=42), time.monotonic()))

    def send(self, topic: str, message: object) -> None:
        self.sent.append((time.monotonic(), topic, message))

    def take_received(self):
        with self._lock:
            taken, self._received = self._received, []
        return taken

    def close(self) -> None:
        self._stop.set()


@pytest.fixture
def robot():
    link = FakeCrowBot()
    yield link
    link.close()


def spec(code: str, duration_s: float = 1.5, clock: Clock = Clock.REALTIME) -> RunSpec:
    return RunSpec(
        robot="crowbot", world="wall_approach",
        nodes=(NodeSpec("driver", code, "driver.py"),), clock=clock, duration_s=duration_s,
    )  # fmt: skip


def controls(link: FakeCrowBot) -> list[tuple[float, float]]:
    return [(m.linear.x, m.angular.z) for _, topic, m in link.sent if topic == "Control"]


def test_a_node_drives_the_robot_through_the_limits_and_it_stops_at_the_end(
    tmp_path, launcher, robot
):
    backend = HardwareRobot("crowbot", robot, LIMITS)
    result = Run(spec(DRIVER), launcher, tmp_path / "run", backend=backend).execute()
    assert result.state is RunState.FINISHED, result.reason
    sent = controls(robot)
    assert len(sent) > 10
    assert max(linear for linear, _ in sent) == pytest.approx(0.2)  # clamped to the limit
    assert sent[0][0] < 0.2  # ramped up from rest
    assert sent[-1] == (0.0, 0.0)  # zero at the end
    leds = [m for _, topic, m in robot.sent if topic == "Leds"]
    assert leds and list(leds[-1].data) == [0, 0, 0]
    assert result.nodes["driver"]["wakes"] > 10
    assert any(
        "saw 42" in line for line in (tmp_path / "run/logs/driver.log").read_text().split("\n")
    )


def test_the_applied_command_is_recorded_beside_the_students_with_its_limit(
    tmp_path, launcher, robot
):
    backend = HardwareRobot("crowbot", robot, LIMITS)
    result = Run(spec(DRIVER), launcher, tmp_path / "run", backend=backend).execute()
    assert result.state is RunState.FINISHED, result.reason
    recorded: dict[str, list[object]] = {}
    with (tmp_path / "run/recording.mcap").open("rb") as stream:
        for schema, channel, message in make_reader(stream).iter_messages():
            cls = get_message_class(schema.name)
            recorded.setdefault(channel.topic, []).append(cls.deserialize(message.data))
    asked = [m.linear.x for m in recorded["/Control"]]
    applied = [m.linear.x for m in recorded["/Control_applied"]]
    assert asked.count(5.0) >= 10  # the student's raw command
    assert max(applied) == pytest.approx(0.2) and applied[0] < 0.2  # clamped and ramped
    limits = [m.data for m in recorded["/Control_limit"]]
    # Before the node's first command the watchdog held the robot at zero; then the step from
    # rest was both clamped and ramped, and once at speed only clamped.
    assert limits[0] == "watchdog"
    assert limits[1] == "max_linear_m_s,max_linear_accel_m_s2"
    assert limits[-1] == "max_linear_m_s"


def test_the_watchdog_stops_the_robot_when_the_node_goes_quiet(tmp_path, launcher, robot):
    quiet = DRIVER.replace('    return {"Control": (5.0, 0.0)}', (
        '    if obs.time < 0.3:\n        return {"Control": (0.1, 0.0)}\n    return None'
    ))  # fmt: skip
    backend = HardwareRobot("crowbot", robot, LIMITS, watchdog_s=0.5)
    Run(spec(quiet, duration_s=2.0), launcher, tmp_path / "run", backend=backend).execute()
    assert backend.watchdog.trips == 1
    times = [t for t, topic, m in robot.sent if topic == "Control" and m.linear.x == 0.0]
    moving = [t for t, topic, m in robot.sent if topic == "Control" and m.linear.x > 0.0]
    stop_after_s = min(t for t in times if t > moving[-1]) - moving[-1]
    assert 0.45 <= stop_after_s <= 0.7  # 500 ms after the last command, not at the end


def test_a_lost_connection_ends_the_run_with_that_reason(tmp_path, launcher, robot):
    backend = HardwareRobot("crowbot", robot, LIMITS)
    run = Run(spec(DRIVER, duration_s=10.0), launcher, tmp_path / "run", backend=backend)

    def unplug() -> None:
        robot.lost_reason = "robot disconnected"
        robot.connected = False

    threading.Timer(0.8, unplug).start()
    result = run.execute()
    assert result.state is RunState.FAILED
    assert result.reason == "failed: robot disconnected"
    assert result.duration_s < 3


def test_a_robot_that_stops_sending_ends_the_run_and_is_stopped(tmp_path, launcher, robot):
    backend = HardwareRobot("crowbot", robot, LIMITS)
    run = Run(spec(DRIVER, duration_s=10.0), launcher, tmp_path / "run", backend=backend)
    frozen_at: list[float] = []

    def freeze_once_driving() -> None:
        deadline = time.monotonic() + 20.0
        while not any(m.linear.x > 0.1 for _, m in controls_sent()):
            if time.monotonic() > deadline:
                return
            time.sleep(0.01)
        frozen_at.append(time.monotonic())
        robot.frozen.set()

    def controls_sent() -> list[tuple[float, object]]:
        return [(t, m) for t, topic, m in list(robot.sent) if topic == "Control"]

    threading.Thread(target=freeze_once_driving, daemon=True).start()
    result = run.execute()
    assert result.state is RunState.FAILED
    assert result.reason == "failed: robot stopped sending Distance for 0.3 s"
    # Zero velocity went out within the bound (300 ms after the last Distance) plus a few polls.
    sent = [(t, m) for t, m in controls_sent() if t > frozen_at[0]]
    stops = [t for t, m in sent if m == Twist()]
    assert stops and 0.2 <= stops[0] - frozen_at[0] <= 0.45
    assert not [t for t, m in sent if m.linear.x and t > stops[0]]  # nothing moved it after


class FakeCrowBotAllSensors(FakeCrowBot):
    """A CrowBot that says it publishes Distance, Light and Line and sends all three at 20 Hz,
    Light 10 ms before the others (as a firmware's loop sends them in turn)."""

    publishes = frozenset({"Distance", "Light", "Line"})

    def _publish(self) -> None:
        while not self._stop.wait(0.05):
            if self.frozen.is_set():
                continue
            now = time.monotonic()
            with self._lock:
                self._received.append(("Light", LIGHT(data=[100, 100]), now - 0.01))
                self._received.append(("Line", LIGHT(data=[0, 0]), now))
                self._received.append(("Distance", Int32(data=42), now))


LIGHT = get_message_class("std_msgs/Int32MultiArray")


def test_a_frozen_robot_is_said_to_have_stopped_sending_what_the_node_reads(tmp_path, launcher):
    """Every topic stops at once; Light, heard last 10 ms earlier, trips first, but the node
    reads only Distance: the run's end names Distance (issue 33)."""
    robot = FakeCrowBotAllSensors()
    try:
        backend = HardwareRobot("crowbot", robot, LIMITS)
        run = Run(spec(DRIVER, duration_s=10.0), launcher, tmp_path / "run", backend=backend)
        threading.Timer(1.0, robot.frozen.set).start()
        result = run.execute()
    finally:
        robot.close()
    assert result.state is RunState.FAILED
    assert result.reason == "failed: robot stopped sending Distance for 0.3 s"


def test_a_real_robot_needs_the_realtime_clock(tmp_path, launcher, robot):
    with pytest.raises(RunSpecError, match="realtime"):
        Run(spec(DRIVER, clock=Clock.LOCKSTEP), launcher, tmp_path / "run",
            backend=HardwareRobot("crowbot", robot, LIMITS))  # fmt: skip


class _ReadLateLink:
    """A link whose reader thread was not scheduled: it says how far it has read
    (`listened_until_s`), and what the robot sent after that has not reached the inbox yet."""

    connected = True
    lost_reason = ""
    publishes = frozenset({"Distance"})

    def __init__(self) -> None:
        self.listened_until_s: float | None = 0.0
        self.inbox: list[tuple[str, object, float]] = []
        self.sent: list[tuple[str, object]] = []

    def send(self, topic: str, message: object) -> None:
        self.sent.append((topic, message))

    def take_received(self):
        taken, self.inbox = self.inbox, []
        return taken


def test_silence_counts_only_as_far_as_the_host_has_read():
    now = [0.0]
    link = _ReadLateLink()
    backend = HardwareRobot("crowbot", link, LIMITS, clock=lambda: now[0])
    backend.reset()
    link.inbox.append(("Distance", Int32(data=42), 0.1))
    link.listened_until_s = 0.11
    backend.step(0.1)
    # The host's reader stalls for 1 s: the robot may have talked all along, unread.
    now[0] = 1.1
    backend.step(0.1)  # no RobotSilent: nothing is known past 0.11 s
    link.sent.clear()  # (the command watchdog's zero: the node sent nothing for 0.5 s)
    # The reader catches up and finds the robot did stop: 1.0 s of real silence.
    link.listened_until_s = 1.1
    with pytest.raises(RobotSilent, match=r"robot stopped sending Distance for 1\.0 s"):
        backend.step(0.1)
    assert link.sent[-1] == ("Control", Twist())  # the wheels were stopped


def test_a_link_that_does_not_say_how_far_it_read_is_judged_by_the_clock():
    now = [0.0]
    link = _ReadLateLink()
    link.listened_until_s = None
    backend = HardwareRobot("crowbot", link, LIMITS, clock=lambda: now[0])
    backend.reset()
    now[0] = 0.4
    with pytest.raises(RobotSilent, match=r"robot stopped sending Distance for 0\.4 s"):
        backend.step(0.1)
