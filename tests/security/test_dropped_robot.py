"""Issue 33, findings 3 and 14, on the wire: a CrowBot firmware emulator (tests/hardware/
crowbot_firmware.py, real rosserial framing, no watchdog of its own: it holds its last command)
drives through `robodojo serve`.

Finding 3: the link dropped mid-run, the firmware reconnected at once, was sent no zero, and
drove on into the wall. Now every robot that completes a rosserial handshake is sent zero
velocity and LEDs off before anything else, and the run whose link dropped ends saying so.
Measured through a TCP relay (tests/hardware/wifi_relay.py, on loopback, no delay) that drops
the connection mid-run: the zero reaches the robot within 100 ms of its reconnection.

Finding 14: a second connection from an idle robot's address replaced its session, but the old
connection stayed open and its readings reached later runs. Now it is closed at once, and
nothing it sends reaches a run."""

from __future__ import annotations

import contextlib
import io
import json
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass

import pytest
from mcap.reader import make_reader

from sandbox.msgs.std_msgs import Int32
from tests.api.conftest import LabServer, free_port, start_server, stop_server, wait_for_end
from tests.hardware.crowbot_firmware import CrowBotFirmware, FirmwareOptions
from tests.hardware.robot_process import REPO, RobotProcess
from tests.waiting import wait_until

pytestmark = pytest.mark.slow  # a server, a relay and a robot process; runs on the robot

ROBOT = "crowbot-d"
ZERO_WITHIN_S = 0.1  # [s] from the robot's reconnection to its first zero velocity (the issue)
DRIVE = """\
import rospy
from geometry_msgs.msg import Twist

rospy.init_node("creep")
pub = rospy.Publisher("Control", Twist, queue_size=1)
rate = rospy.Rate(10)
while not rospy.is_shutdown():
    cmd = Twist()
    cmd.linear.x = 0.125
    pub.publish(cmd)
    rate.sleep()
"""
# Reads the robot's Distance and commands nothing: whatever reaches the run is recorded.
LISTEN = """\
import rospy
from std_msgs.msg import Int32

rospy.init_node("listen")
rospy.Subscriber("Distance", Int32, lambda msg: None)
rospy.spin()
"""


class LoopbackRelay:
    """tests/hardware/wifi_relay.py between the robot and the server, on loopback, with no
    delay, jitter or loss: only its `drop` (close every connection now) is wanted here."""

    def __init__(self, target_port: int) -> None:
        self.port = free_port()
        self.events: list[dict] = []
        self._lock = threading.Lock()
        self._process = subprocess.Popen(
            [sys.executable, "-m", "tests.hardware.wifi_relay", "127.0.0.1", str(self.port),
             "127.0.0.1", str(target_port), "--delay", "0", "--jitter", "0", "--loss", "0"],
            cwd=REPO, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
        )  # fmt: skip
        threading.Thread(target=self._read, name="relay-events", daemon=True).start()
        wait_until(lambda: self.named("ready"), 10, "the relay listens")

    def _read(self) -> None:
        assert self._process.stdout is not None
        for line in self._process.stdout:
            with self._lock:
                self.events.append(json.loads(line))

    def named(self, name: str, after_s: float = 0.0) -> list[dict]:
        with self._lock:
            return [e for e in self.events if e["event"] == name and e["t"] >= after_s]

    def drop(self) -> float:
        """Close the connections open now (the robot sees its socket close); the time [s]."""
        assert self._process.stdin is not None
        dropped_s = time.monotonic()
        self._process.stdin.write("drop\n")
        self._process.stdin.flush()
        return dropped_s

    def stop(self) -> None:
        with contextlib.suppress(OSError, ValueError):
            assert self._process.stdin is not None
            self._process.stdin.close()  # the relay exits when its stdin closes
        try:
            self._process.wait(5.0)
        except subprocess.TimeoutExpired:
            self._process.kill()
            self._process.wait(5.0)
        if self._process.stdout is not None:
            self._process.stdout.close()


@dataclass
class Bench:
    server: LabServer
    rosserial_port: int

    def connection(self) -> str:
        robots = self.server.admin().get("/api/admin/robots").json()["robots"]
        return next(r for r in robots if r["name"] == ROBOT)["connection"]

    def wait_connected(self, what: str) -> None:
        wait_until(lambda: self.connection() == "connected", 10, what, poll_s=0.05)

    def start_run(self, student_name: str, code: str, duration_s: float) -> tuple[object, str]:
        student = self.server.student(student_name)
        assert student.post(f"/api/hardware/{ROBOT}/queue").status_code in (200, 201)
        started = student.post(
            "/api/runs",
            json={"robot": "crowbot", "world": "wall_approach", "hardware": ROBOT,
                  "duration": duration_s, "nodes": [{"name": "node", "code": code}]},
        )  # fmt: skip
        assert started.status_code == 201, started.text
        return student, started.json()["id"]


@pytest.fixture(scope="module")
def bench(tmp_path_factory) -> Iterator[Bench]:
    # No simulation gate: these runs go straight to the robot.
    server = start_server(tmp_path_factory.mktemp("dropped"), {"ROBODOJO_HARDWARE_GATE": "false"})
    try:
        admin = server.admin()
        port = admin.get("/api/admin/status").json()["hardware"]["rosserial_port"]
        made = admin.post(
            "/api/admin/robots", json={"name": ROBOT, "kind": "crowbot", "address": "127.0.0.1"}
        )
        assert made.status_code == 201, made.text
        server.close_clients()
        yield Bench(server, port)
    finally:
        stop_server(server)


def test_a_robot_that_reconnects_after_a_drop_is_stopped_at_once(bench):
    relay = LoopbackRelay(bench.rosserial_port)
    robot = RobotProcess("127.0.0.1", relay.port, reconnect=True).start()
    try:
        bench.wait_connected("the robot connected through the relay")
        student, run_id = bench.start_run("ada", DRIVE, duration_s=30)
        assert robot.wait_for(lambda r: (r.linear or 0) > 0.1, 15), "the run never drove it"
        dropped_s = relay.drop()
        run = wait_for_end(student, run_id, timeout_s=10)
        # The firmware reconnects 0.2 s after it saw its socket close (ArduinoTcpHardware).
        reconnected = wait_until(
            lambda: relay.named("connected", dropped_s), 5, "the robot reconnected"
        )[0]
        assert robot.wait_for(lambda r: r.t >= dropped_s and r.linear == 0.0, 5), (
            "the reconnected robot was never sent zero velocity: it drives on at its last duty"
        )
        zero_s = min(r.t for r in robot.received_after(dropped_s) if r.linear == 0.0)
        zero_after_s = zero_s - reconnected["t"]
        print(f"\nzero velocity {zero_after_s * 1000:.1f} ms after the reconnection")
        assert 0 <= zero_after_s < ZERO_WITHIN_S, zero_after_s
        leds = [r for r in robot.received_after(dropped_s, "Leds") if r.leds == [0, 0, 0]]
        assert leds and leds[0].t - reconnected["t"] < ZERO_WITHIN_S, "LEDs were not put off"
        # Nothing drove it after that zero: the new session is at rest until the next run.
        assert not [r for r in robot.received_after(zero_s) if r.linear]
        assert run["state"] == "failed", run
        assert "lost the link to the robot" in run["reason"], run["reason"]
        bench.wait_connected("the reconnected robot is connected")
    finally:
        robot.stop()
        relay.stop()


def recorded_distances(student, run_id: str) -> list[int]:
    recording = student.get(f"/api/runs/{run_id}/recording.mcap").content
    return [
        Int32.deserialize(message.data).data
        for _, channel, message in make_reader(io.BytesIO(recording)).iter_messages()
        if channel.topic == "/Distance"
    ]


OLD_COUNTER_START = 1_000_000  # the replaced robot's Distance values: never a new one's


def test_a_replaced_session_is_closed_and_reaches_no_run(bench):
    old = CrowBotFirmware("127.0.0.1", bench.rosserial_port, FirmwareOptions(counter_distance=True))
    old._counter = OLD_COUNTER_START  # its readings are told apart from the new one's
    old.start()
    new = None
    try:
        assert old.wait_until(lambda: old.configured, 10)
        bench.wait_connected("the first connection is the robot")
        # A second connection from the idle robot's address (a reboot) replaces the session.
        new = CrowBotFirmware(
            "127.0.0.1", bench.rosserial_port, FirmwareOptions(counter_distance=True)
        ).start()
        assert new.wait_until(lambda: new.configured, 10), "the second connection was refused"
        assert old.wait_until(lambda: not old.connected, 1.0), (
            "the replaced connection is still open: its readings would reach the next run"
        )
        assert old.tx_stops == 1 and old.received_on("Control")[-1].linear.x == 0.0
        bench.wait_connected("the robot is connected on its new session")
        student, run_id = bench.start_run("ben", LISTEN, duration_s=2)
        run = wait_for_end(student, run_id, timeout_s=20)
        assert run["state"] == "finished", run["reason"]
        distances = recorded_distances(student, run_id)
        assert len(distances) >= 20  # 20 Hz for 2 s, from the new session
        assert max(distances) < OLD_COUNTER_START, "the replaced session's readings were recorded"
    finally:
        old.stop()
        if new is not None:
            new.stop()
