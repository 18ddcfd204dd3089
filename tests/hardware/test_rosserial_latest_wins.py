"""Latest-wins commands (server.py): a robot that freezes without closing its socket gets, when it
resumes, the newest command and the stop, never the backlog of commands sent meanwhile.

The robot is the firmware emulator in its own process, frozen with SIGSTOP (a stalled firmware or
a stuck WiFi link; its kernel keeps acknowledging, so TCP alone would queue every command)."""

from __future__ import annotations

import threading
import time

import pytest

from sandbox.msgs.geometry_msgs import Twist, Vector3
from server.hardware.rosserial.server import RobotConnection, RosserialHandler, RosserialServer
from tests.hardware.robot_process import Received, RobotProcess

LOOPBACK = "127.0.0.1"
COMMAND_HZ = 20.0  # [Hz] the student's node commands on a timer, whatever the robot does
FREEZE_S = 3.0  # [s] (the issue measured 10 s: bench/bench_rosserial.py --freeze 10)
TWIST_FRAME_BYTES = 56  # [bytes] 8 frame bytes + 6 float64


class Connected(RosserialHandler):
    def __init__(self) -> None:
        self.robots: list[RobotConnection] = []

    def on_robot_connected(self, robot: RobotConnection) -> None:
        self.robots.append(robot)


def freeze_and_count(freeze_s: float, port_host: str = LOOPBACK) -> tuple[list[Received], int]:
    """Command at COMMAND_HZ, freeze the robot for `freeze_s`, send the stop, resume it: what it
    received after resuming, and how many commands were sent while it was frozen."""
    handler = Connected()
    with (
        RosserialServer(handler, host=port_host, port=0) as server,
        RobotProcess(LOOPBACK, server.port) as robot_process,
    ):
        deadline = time.monotonic() + 10.0
        while not handler.robots and time.monotonic() < deadline:
            time.sleep(0.01)
        assert handler.robots, f"the robot did not connect: {robot_process.stderr()}"
        (robot,) = handler.robots
        commanding = threading.Event()
        commanding.set()
        sent = [0]

        def student_node() -> None:
            while commanding.is_set():
                sent[0] += 1
                robot.send("Control", Twist(linear=Vector3(x=0.05 + 1e-6 * sent[0])))
                time.sleep(1.0 / COMMAND_HZ)

        node = threading.Thread(target=student_node, daemon=True)
        node.start()
        try:
            assert robot_process.wait_for(lambda r: r.topic == "Control")
            robot_process.freeze()
            frozen_at = sent[0]
            time.sleep(freeze_s)  # the freeze itself is the scenario
        finally:
            commanding.clear()
            node.join()
        sent_while_frozen = sent[0] - frozen_at
        robot.send("Control", Twist(), urgent=True)  # the stop a watchdog sends
        resumed_s = robot_process.resume()
        assert robot_process.wait_for(lambda r: r.t >= resumed_s and r.linear == 0.0, 5.0)
        # Anything still held goes out at the robot's first frame after resuming; let it.
        time.sleep(0.3)
        return robot_process.received_after(resumed_s), sent_while_frozen


@pytest.mark.slow
def test_a_frozen_robot_gets_the_newest_command_and_the_stop_not_a_backlog() -> None:
    after, sent_while_frozen = freeze_and_count(FREEZE_S)
    assert sent_while_frozen >= FREEZE_S * COMMAND_HZ * 0.8
    # At most one command written after the robot's last frame, then the stop.
    assert len(after) <= 2, [r.linear for r in after]
    assert after[-1].linear == 0.0
    assert sum(r.bytes for r in after) <= 2 * TWIST_FRAME_BYTES


def test_a_live_robot_gets_every_command_at_its_loop_rate() -> None:
    handler = Connected()
    with (
        RosserialServer(handler, host=LOOPBACK, port=0) as server,
        RobotProcess(LOOPBACK, server.port, rate_hz=20.0) as robot_process,
    ):
        deadline = time.monotonic() + 10.0
        while not handler.robots and time.monotonic() < deadline:
            time.sleep(0.01)
        (robot,) = handler.robots
        started_s = time.monotonic()
        for index in range(20):  # 20 commands at 10 Hz: slower than the robot's 20 Hz loop
            robot.send("Control", Twist(linear=Vector3(x=0.001 * (index + 1))))
            time.sleep(0.1)
        assert robot_process.wait_for(lambda r: r.linear == 0.02, 2.0)
        got = [r.linear for r in robot_process.received_after(started_s)]
        assert got == [0.001 * (i + 1) for i in range(20)]
        assert robot.commands_replaced == 0
