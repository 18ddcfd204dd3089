"""CreateDriver against the Create emulator over a pseudo-terminal: the real pyserial path, real
threads, wall-clock time. Tolerances leave room for a loaded test machine."""

from __future__ import annotations

import errno
import math
import os
import random
import threading
import time
from collections.abc import Callable, Iterator

import pytest

serial = pytest.importorskip("serial", reason="CreateDriver needs pyserial")

from sandbox.msgs import get_message_class  # noqa: E402
from sandbox.msgs.geometry_msgs import Twist, Vector3  # noqa: E402
from server.hardware.create import oi, topics  # noqa: E402
from server.hardware.create import port as port_module  # noqa: E402
from server.hardware.create.driver import (  # noqa: E402
    CreateDriver,
    CreateNoAnswerError,
    CreatePortError,
    CreateState,
    CreateStateError,
)
from tests.hardware.create_emulator import CreateEmulator, Room  # noqa: E402

ZERO_DRIVE = bytes(4)  # Drive Direct data: right 0, left 0


def twist(linear_m_s: float = 0.0, angular_rad_s: float = 0.0) -> Twist:
    return Twist(linear=Vector3(x=linear_m_s), angular=Vector3(z=angular_rad_s))


def wait_for(condition: Callable[[], bool], timeout_s: float = 3.0) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.005)
    return condition()


def drive_for(driver: CreateDriver, command: Twist, duration_s: float) -> None:
    """Send `command` at 20 Hz for `duration_s`, as a controller would, then zero."""
    end = time.monotonic() + duration_s
    while (left := end - time.monotonic()) > 0:
        driver.command(command)
        time.sleep(min(0.05, left))
    driver.command(twist())


class Recorder:
    """on_message / on_state sink, thread-safe."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.messages: list[tuple[str, object]] = []
        self.states: list[tuple[CreateState, str | None]] = []

    def on_message(self, topic: str, message: object) -> None:
        with self.lock:
            self.messages.append((topic, message))

    def on_state(self, state: CreateState, reason: str | None) -> None:
        with self.lock:
            self.states.append((state, reason))

    def topic(self, name: str) -> list:
        with self.lock:
            return [message for topic, message in self.messages if topic == name]


@pytest.fixture
def emulator() -> Iterator[CreateEmulator]:
    with CreateEmulator() as emulator:
        yield emulator


@pytest.fixture
def recorder() -> Recorder:
    return Recorder()


def open_driver(emulator: CreateEmulator, recorder: Recorder, **options) -> CreateDriver:
    driver = CreateDriver(
        emulator.port, on_message=recorder.on_message, on_state=recorder.on_state, **options
    )
    driver.open()
    return driver


# --- the contract with the simulated turtlebot ---------------------------------------------------


def test_topics_and_types_match_the_simulated_turtlebot(emulator, recorder):
    from server.sim.robots.turtlebot import TurtleBot

    robot = TurtleBot()
    sensors = robot.build_sensors()
    assert topics.TOPIC_CMD_VEL in robot.commands
    assert robot.commands[topics.TOPIC_CMD_VEL][0] is Twist
    driver = open_driver(emulator, recorder)
    try:
        assert wait_for(lambda: recorder.topic("odom") and recorder.topic("bumper"))
        for topic in (topics.TOPIC_ODOM, topics.TOPIC_BUMPER):
            assert type(recorder.topic(topic)[-1]) is sensors[topic].msg_type
        odom = recorder.topic("odom")[-1]
        assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_link")
        assert abs(odom.header.stamp.to_sec() - time.time()) < 5.0
        assert recorder.topic("bumper")[-1].data == [0, 0]
        assert get_message_class("nav_msgs/Odometry") is type(odom)
    finally:
        driver.close()


def test_open_starts_safe_mode_and_streams_what_it_needs(emulator, recorder):
    driver = open_driver(emulator, recorder)
    try:
        assert driver.state is CreateState.STREAMING
        assert emulator.mode is oi.OIMode.SAFE
        assert emulator.commands(oi.Opcode.STREAM) == [bytes([4, 7, 35, 43, 44])]
        codes = [code for code, _ in emulator.received]
        assert codes[:3] == [oi.Opcode.START, oi.Opcode.SAFE, oi.Opcode.STREAM]
        assert driver.oi_mode is oi.OIMode.SAFE
        assert driver.problem is None
    finally:
        driver.close()
    assert [state for state, _ in recorder.states] == [
        CreateState.CONNECTING,
        CreateState.STREAMING,
        CreateState.STOPPED,
        CreateState.CLOSED,
    ]


def test_full_mode_when_asked(emulator, recorder):
    with CreateDriver(emulator.port, mode="full") as driver:
        assert emulator.mode is oi.OIMode.FULL
        assert driver.oi_mode is oi.OIMode.FULL


# --- driving -------------------------------------------------------------------------------------


def test_forward_one_second_at_0_2_m_s(emulator, recorder):
    driver = open_driver(emulator, recorder)
    try:
        drive_for(driver, twist(0.2), 1.0)
        assert emulator.commands(oi.Opcode.DRIVE_DIRECT)[0] == bytes([0, 200, 0, 200])
        true_x, true_y, _ = emulator.pose()
        assert wait_for(lambda: abs(driver.pose.x_m - emulator.pose()[0]) < 0.002)
        assert true_x == pytest.approx(0.2, abs=0.02)
        assert wait_for(
            lambda: abs(recorder.topic("odom")[-1].pose.pose.position.x - true_x) < 0.003
        )
        assert recorder.topic("odom")[-1].pose.pose.position.y == pytest.approx(true_y, abs=0.002)
        speeds = [m.twist.twist.linear.x for m in recorder.topic("odom")]
        assert max(speeds) == pytest.approx(0.2, abs=0.015)
    finally:
        driver.close()


def test_odometry_speed_when_an_adapter_bunches_frames(recorder):
    # Four frames (60 ms) at a time: receive times say nothing about when the robot measured;
    # the driver counts 15 ms per frame instead.
    with CreateEmulator(frames_per_delivery=4) as emulator:
        driver = open_driver(emulator, recorder)
        try:
            drive_for(driver, twist(0.2), 1.0)
            speeds = [m.twist.twist.linear.x for m in recorder.topic("odom")]
            moving = [speed for speed in speeds if speed > 0.1]
            assert len(moving) >= 5
            assert max(moving) == pytest.approx(0.2, abs=0.015)
            assert min(moving[1:-1]) == pytest.approx(0.2, abs=0.015)
        finally:
            driver.close()


def test_turn_a_quarter(emulator, recorder):
    driver = open_driver(emulator, recorder)
    try:
        drive_for(driver, twist(0.0, 1.0), math.pi / 2)
        assert emulator.commands(oi.Opcode.DRIVE_DIRECT)[0] == bytes([0, 118, 0xFF, 0x8A])
        _, _, true_yaw = emulator.pose()
        assert true_yaw == pytest.approx(math.pi / 2, abs=0.1)
        assert wait_for(lambda: abs(driver.pose.yaw_rad - emulator.pose()[2]) < 0.01)

        def odom_yaw() -> float:
            odom = recorder.topic("odom")[-1]
            return 2.0 * math.atan2(odom.pose.pose.orientation.z, odom.pose.pose.orientation.w)

        assert wait_for(lambda: abs(odom_yaw() - true_yaw) < 0.01)  # the next 20 Hz message
        assert math.hypot(driver.pose.x_m, driver.pose.y_m) < 0.005
    finally:
        driver.close()


def test_odometry_through_the_encoder_wraparound(recorder):
    with CreateEmulator(encoder_start=(65400, 65400)) as emulator:
        driver = open_driver(emulator, recorder)
        try:
            drive_for(driver, twist(0.2), 0.6)  # ~270 counts: both counters roll over
            assert emulator.encoder_counts()[0] < 65400
            assert wait_for(lambda: abs(driver.pose.x_m - emulator.pose()[0]) < 0.002)
            assert driver.pose.x_m == pytest.approx(0.12, abs=0.02)
        finally:
            driver.close()


def test_bumper_head_on_and_the_wheels_stall(recorder):
    # The wall at x = 0.6 m touches the 0.17 m body at x = 0.43 m, 0.13 m ahead.
    with CreateEmulator(room=Room(max_x_m=0.6), start_pose=(0.3, 0.0, 0.0)) as emulator:
        driver = open_driver(emulator, recorder)
        try:
            drive_for(driver, twist(0.2), 1.2)
            assert emulator.pose()[0] == pytest.approx(0.43, abs=1e-6)
            assert wait_for(lambda: recorder.topic("bumper")[-1].data == [1, 1])
            assert driver.pose.x_m == pytest.approx(0.13, abs=0.003)  # no slip counted
            drive_for(driver, twist(-0.2), 0.3)  # back off: the switches open
            assert wait_for(lambda: recorder.topic("bumper")[-1].data == [0, 0])
        finally:
            driver.close()


def test_bumper_sides(recorder):
    # Heading 0.5 rad to the left of a wall ahead: the wall is on the robot's right.
    room = Room(max_x_m=0.5)
    with CreateEmulator(room=room, start_pose=(0.25, 0.0, 0.5)) as emulator:
        driver = open_driver(emulator, recorder)
        try:
            drive_for(driver, twist(0.2), 0.8)
            assert wait_for(lambda: recorder.topic("bumper")[-1].data == [0, 1])
        finally:
            driver.close()
    with CreateEmulator(room=room, start_pose=(0.25, 0.0, -0.5)) as emulator:
        driver = open_driver(emulator, recorder)
        try:
            drive_for(driver, twist(0.2), 0.8)
            assert wait_for(lambda: recorder.topic("bumper")[-1].data == [1, 0])
        finally:
            driver.close()


def test_a_bump_is_published_at_once_not_at_the_next_tick(recorder):
    room = Room(max_x_m=0.5)
    with CreateEmulator(room=room, start_pose=(0.32, 0.0, 0.0)) as emulator:
        driver = open_driver(emulator, recorder, publish_rate_hz=1.0)
        try:
            driver.command(twist(0.2))
            assert wait_for(lambda: recorder.topic("bumper")[-1].data == [1, 1], 0.6)
        finally:
            driver.close()


def test_stop_sends_zero_velocity_then_passive(emulator, recorder):
    driver = open_driver(emulator, recorder)
    driver.command(twist(0.3))
    assert wait_for(lambda: emulator.left_mm_s == 300)
    driver.stop()
    assert emulator.commands(oi.Opcode.DRIVE_DIRECT)[-1] == ZERO_DRIVE
    tail = [code for code, _ in emulator.received[-3:]]
    assert tail == [oi.Opcode.DRIVE_DIRECT, oi.Opcode.PAUSE_RESUME_STREAM, oi.Opcode.START]
    assert wait_for(lambda: emulator.mode is oi.OIMode.PASSIVE)
    assert (emulator.left_mm_s, emulator.right_mm_s) == (0, 0)
    assert driver.state is CreateState.STOPPED
    with pytest.raises(CreateStateError, match="make a new CreateDriver"):
        driver.command(twist(0.1))
    driver.stop()  # twice is fine
    driver.close()
    driver.close()
    assert driver.state is CreateState.CLOSED


def test_a_stale_command_is_replaced_by_zero(emulator, recorder):
    driver = open_driver(emulator, recorder, command_latch_s=0.2)
    try:
        driver.command(twist(0.2))
        assert wait_for(lambda: emulator.left_mm_s == 200)
        assert wait_for(lambda: emulator.left_mm_s == 0, 1.0)
        assert emulator.commands(oi.Opcode.DRIVE_DIRECT)[-1] == ZERO_DRIVE
    finally:
        driver.close()


def test_wrong_commands_fail_with_a_sentence(emulator, recorder):
    fresh = CreateDriver(emulator.port)
    with pytest.raises(CreateStateError, match="call open"):
        fresh.command(twist(0.1))
    driver = open_driver(emulator, recorder)
    try:
        with pytest.raises(TypeError, match="geometry_msgs/Twist"):
            driver.command("forward")
        driver.command(twist(0.2))
        with pytest.raises(ValueError, match="finite"):
            driver.command(twist(float("nan")))
        assert wait_for(lambda: emulator.commands(oi.Opcode.DRIVE_DIRECT)[-1:] == [ZERO_DRIVE])
        with pytest.raises(CreateStateError, match="open\\(\\) is called once"):
            driver.open()
    finally:
        driver.close()


# --- a bad line ----------------------------------------------------------------------------------


def test_a_garbage_burst_is_dropped_and_counted(emulator, recorder):
    driver = open_driver(emulator, recorder)
    try:
        garbage = bytes(
            random.Random(7).choice([b for b in range(256) if b != 19]) for _ in range(300)
        )
        frames_before = driver.stats.frames
        emulator.inject(garbage)
        assert wait_for(lambda: driver.stats.frames > frames_before + 10)
        assert driver.stats.discarded_bytes == len(garbage)
        assert driver.stats.bad_frames == 0
        # A frame-shaped burst with a wrong checksum is a bad frame; the next good one parses.
        fake = bytearray(oi.encode_stream_frame({7: 3, 35: 2, 43: 0, 44: 0}))
        fake[-1] ^= 0xFF
        emulator.inject(bytes(fake))
        frames_before = driver.stats.frames
        assert wait_for(lambda: driver.stats.frames > frames_before + 3)
        assert driver.stats.bad_frames == 1
        assert driver.state is CreateState.STREAMING
        assert recorder.topic("bumper")[-1].data == [0, 0]  # the fake bump never came through
    finally:
        driver.close()


def test_silence_is_detected_with_a_sentence_and_recovery_too(emulator, recorder):
    driver = open_driver(emulator, recorder, silence_timeout_s=0.2)
    try:
        emulator.go_silent()
        assert wait_for(lambda: driver.state is CreateState.SILENT, 1.5)
        assert driver.problem is not None
        assert f"no sensor frame from the Create on {emulator.port} for" in driver.problem
        assert "odometry is frozen" in driver.problem
        assert recorder.states[-1] == (CreateState.SILENT, driver.problem)
        driver.command(twist(0.1))  # still allowed: the robot may only be slow to answer
        emulator.speak_again()
        assert wait_for(lambda: driver.state is CreateState.STREAMING, 1.5)
        assert driver.problem is None
    finally:
        driver.close()


def test_leaving_safe_mode_is_reported(emulator, recorder):
    driver = open_driver(emulator, recorder)
    try:
        emulator.drop_wheels()
        assert wait_for(lambda: driver.oi_mode is oi.OIMode.PASSIVE)
        assert driver.problem is not None
        assert "Passive mode, not Safe (a wheel dropped?)" in driver.problem
        heard = len(emulator.received)
        driver.command(twist(0.2))
        assert wait_for(lambda: len(emulator.received) > heard)
        assert emulator.left_mm_s == 0  # the robot ignores drive commands in Passive
        emulator.put_down()
        driver.rearm()
        assert wait_for(lambda: driver.oi_mode is oi.OIMode.SAFE)
        assert driver.problem is None
        driver.command(twist(0.2))
        assert wait_for(lambda: emulator.left_mm_s == 200)
    finally:
        driver.close()


def test_stop_with_off_sends_stop(emulator, recorder):
    driver = open_driver(emulator, recorder, stop_with="off")
    driver.close()
    assert emulator.received[-1] == (oi.Opcode.STOP, b"")
    assert wait_for(lambda: emulator.mode is oi.OIMode.OFF)


def test_a_pulled_cable_is_reported(emulator, recorder):
    driver = open_driver(emulator, recorder)
    emulator.close()
    assert wait_for(lambda: driver.state is CreateState.SILENT, 2.0)
    assert driver.problem is not None
    assert driver.problem.startswith(f"reading the serial port {emulator.port} failed")
    with pytest.raises(CreatePortError, match="the cable may be unplugged"):
        driver.command(twist(0.1))
    driver.close()  # does not hang on the dead port
    assert driver.state is CreateState.CLOSED


# --- cannot connect ------------------------------------------------------------------------------


def test_a_missing_port_says_so():
    driver = CreateDriver("/dev/ttyUSB-no-such-port")
    with pytest.raises(CreatePortError, match="no such device: is the USB-serial cable plugged"):
        driver.open()
    assert driver.state is CreateState.CLOSED


def test_permission_denied_says_what_to_do(monkeypatch):
    def refuse(*args, **kwargs):
        raise serial.SerialException(errno.EACCES, "could not open port: [Errno 13] denied")

    monkeypatch.setattr(port_module.serial, "Serial", refuse)
    with pytest.raises(CreatePortError, match="permission denied: add the server's user"):
        CreateDriver("/dev/ttyUSB0").open()


def test_a_port_in_use_says_so(emulator, recorder):
    driver = open_driver(emulator, recorder)
    try:
        second = CreateDriver(emulator.port)
        with pytest.raises(CreatePortError, match="another program holds the port"):
            second.open()
        assert driver.state is CreateState.STREAMING
    finally:
        driver.close()


def test_a_robot_that_does_not_answer():
    master, slave = os.openpty()
    try:
        driver = CreateDriver(os.ttyname(slave), connect_timeout_s=0.3)
        started = time.monotonic()
        with pytest.raises(CreateNoAnswerError, match=r"within 0\.3 s: nothing came back: is"):
            driver.open()
        assert time.monotonic() - started < 1.5
        assert driver.state is CreateState.CLOSED
        assert os.read(master, 100).startswith(bytes([128, 131, 148, 4]))
    finally:
        os.close(master)
        os.close(slave)


def test_bytes_that_are_no_frames_suggest_the_baud_rate():
    master, slave = os.openpty()
    stop = threading.Event()

    def chatter() -> None:
        while not stop.is_set():
            os.write(master, b"\xfe\x00\x7f" * 4)
            time.sleep(0.01)

    thread = threading.Thread(target=chatter, daemon=True)
    thread.start()
    try:
        with pytest.raises(CreateNoAnswerError, match="no valid sensor frame: is the baud rate"):
            CreateDriver(os.ttyname(slave), connect_timeout_s=0.3).open()
    finally:
        stop.set()
        thread.join()
        os.close(master)
        os.close(slave)


# --- the emulator itself -------------------------------------------------------------------------


def test_emulator_ignores_commands_in_the_wrong_mode(emulator):
    with serial.Serial(emulator.port, 115200, timeout=0.1) as port:
        drive = oi.encode_drive_direct(100, 100)
        port.write(drive)  # Off: only Start is heard
        time.sleep(0.05)  # not a wait: nothing may happen in this time (no event to wait for)
        assert emulator.received == [] and emulator.left_mm_s == 0
        port.write(oi.encode_opcode(oi.Opcode.START) + drive)  # Passive: heard, not obeyed
        assert wait_for(lambda: len(emulator.received) == 2)
        assert emulator.mode is oi.OIMode.PASSIVE and emulator.left_mm_s == 0
        port.write(oi.encode_opcode(oi.Opcode.SAFE) + drive)  # Safe: obeyed
        assert wait_for(lambda: emulator.left_mm_s == 100)
        port.write(oi.encode_opcode(oi.Opcode.STOP) + oi.encode_sensors(7))  # Off again
        assert wait_for(lambda: emulator.mode is oi.OIMode.OFF)
        assert emulator.left_mm_s == 0
        time.sleep(0.05)  # not a wait: no answer may come in this time (nor in the read's 0.1 s)
        assert port.read(10) == b""  # Sensors went unheard


def test_emulator_streams_every_15_ms(emulator):
    with serial.Serial(emulator.port, 115200, timeout=0.1) as port:
        port.write(oi.encode_opcode(oi.Opcode.START) + oi.encode_stream([7, 43, 44]))
        parser = oi.StreamParser(packet_ids=(7, 43, 44))
        frames: list[dict[int, int]] = []
        started = time.monotonic()
        while len(frames) < 40:
            frames += parser.feed(port.read(64))
        elapsed = time.monotonic() - started
        assert 39 * 0.015 * 0.9 <= elapsed < 3.0  # no faster than one frame per 15 ms
        assert parser.stats.bad_frames == 0


def test_a_stalled_link_gets_the_newest_command_not_a_backlog(emulator, recorder):
    driver = open_driver(emulator, recorder)
    try:
        driver.command(twist(0.1))
        assert wait_for(lambda: emulator.left_mm_s == 100)
        emulator.go_silent()  # the link stalls: no frames, nothing read
        before = len(emulator.commands(oi.Opcode.DRIVE_DIRECT))
        for step in range(1, 51):  # a controller that keeps commanding at 100 Hz
            driver.command(twist(0.1 + 0.002 * step))
            time.sleep(0.01)
        assert driver.commands_waiting == 1 and driver.drives_replaced >= 48
        emulator.speak_again()
        assert wait_for(lambda: emulator.left_mm_s == 200)
        # At most the one command written before the stall showed, then the newest.
        assert len(emulator.commands(oi.Opcode.DRIVE_DIRECT)) - before <= 2
        emulator.go_silent()
        driver.command(twist(0.3))  # a frame came since the last write: written, then...
        driver.command(twist(0.4))  # ...this one waits for the next frame, which never comes
        driver.command(twist())  # a stop never waits: it replaces the held one, written now
        assert driver.commands_waiting == 0
        emulator.speak_again()
        frames = driver.stats.frames
        assert wait_for(lambda: driver.stats.frames >= frames + 3)
        held = oi.encode_drive_direct(400.0, 400.0)[1:]
        assert held not in emulator.commands(oi.Opcode.DRIVE_DIRECT)  # the stop replaced it
    finally:
        driver.close()
