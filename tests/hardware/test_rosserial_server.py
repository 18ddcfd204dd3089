"""server.py over real TCP on a free loopback port, against the CrowBot firmware emulator and
against clients that attack: garbage, bad frames, floods, half-open and non-reading peers."""

from __future__ import annotations

import contextlib
import dataclasses
import os
import socket
import time
from collections.abc import Callable, Iterator

import psutil
import pytest

from sandbox.msgs import Message
from sandbox.msgs.geometry_msgs import Twist, Vector3
from sandbox.msgs.std_msgs import Int32
from server.hardware.rosserial.frames import REQUEST_TOPICS_FRAME, TX_STOP_FRAME, FrameParser
from server.hardware.rosserial.limits import DEFAULT_LIMITS
from server.hardware.rosserial.messages import LogLevel
from server.hardware.rosserial.server import RobotConnection, RosserialHandler, RosserialServer
from server.hardware.rosserial.session import RobotDisconnected, SessionState, TopicError
from tests.hardware.crowbot_firmware import (
    PUBLISHER_IDS,
    WRONG_MD5,
    CrowBotFirmware,
    FirmwareOptions,
    negotiation_frames,
    ros_lib_frame,
)

LOOPBACK = "127.0.0.1"
WALL_NS = 1_692_905_636_631_129_000  # [ns] the host clock the robots are told


class Recorder(RosserialHandler):
    """Keeps every callback; optionally answers each Distance with a Control."""

    def __init__(self, answer: Callable[[RobotConnection, Message], None] | None = None) -> None:
        self.connected: list[RobotConnection] = []
        self.disconnected: list[tuple[RobotConnection, str]] = []
        self.messages: list[tuple[str, str, Message]] = []
        self.logs: list[tuple[str, LogLevel, str]] = []
        self.answer = answer

    def on_robot_connected(self, robot: RobotConnection) -> None:
        self.connected.append(robot)

    def on_robot_disconnected(self, robot: RobotConnection, reason: str) -> None:
        self.disconnected.append((robot, reason))

    def on_message(self, robot: RobotConnection, topic: str, message: Message) -> None:
        self.messages.append((robot.id, topic, message))
        if self.answer is not None and topic == "Distance":
            self.answer(robot, message)

    def on_log(self, robot: RobotConnection, level: LogLevel, line: str) -> None:
        self.logs.append((robot.id, level, line))

    def count(self, robot_id: str, topic: str | None = None) -> int:
        return sum(1 for r, t, _ in list(self.messages) if r == robot_id and topic in (None, t))


def wait_until(predicate: Callable[[], bool], timeout_s: float = 5.0) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.005)
    return predicate()


@contextlib.contextmanager
def serving(handler: RosserialHandler, **limits: float) -> Iterator[RosserialServer]:
    server = RosserialServer(
        handler,
        host=LOOPBACK,
        port=0,
        limits=dataclasses.replace(DEFAULT_LIMITS, **limits),
        clock_ns=lambda: WALL_NS,
    )
    server.start()
    try:
        yield server
    finally:
        server.stop()


def firmware(server: RosserialServer, **options: object) -> CrowBotFirmware:
    return CrowBotFirmware(LOOPBACK, server.port, FirmwareOptions(**options))


def drive_forward(robot: RobotConnection, message: Message) -> None:
    robot.send("Control", Twist(linear=Vector3(x=0.1)))


def read_until_closed(sock: socket.socket, timeout_s: float) -> bytes:
    """Everything the server sends until it closes the connection (or the timeout)."""
    sock.settimeout(timeout_s)
    data = bytearray()
    with contextlib.suppress(TimeoutError, ConnectionResetError):
        while chunk := sock.recv(65536):
            data += chunk
    return bytes(data)


# ----------------------------------------------------------------------------- the CrowBot
def test_the_crowbot_negotiates_streams_and_obeys() -> None:
    handler = Recorder(answer=drive_forward)
    with serving(handler) as server, firmware(server) as robot_fw:
        assert wait_until(lambda: handler.connected and handler.count("robot-1") >= 40)
        (robot,) = handler.connected
        assert robot.state is SessionState.READY and robot.problems == []
        assert {name: t.message_type for name, t in robot.topics.items()} == {
            "Distance": "std_msgs/Int32",
            "Button": "std_msgs/Bool",
            "Light": "std_msgs/Int32MultiArray",
            "Line": "std_msgs/Int32MultiArray",
            "Control": "geometry_msgs/Twist",
            "Leds": "std_msgs/Int32MultiArray",
            "Buzzer": "std_msgs/Bool",
        }
        assert {t for _, t, _ in handler.messages} == {"Distance", "Button", "Light", "Line"}
        # The time sync was answered with the server's clock.
        assert robot_fw.time_answers >= 1
        assert robot_fw.host_time == divmod(WALL_NS, 1_000_000_000)
        # Each Distance was answered with a Control; the simulated robot drove forward.
        start_x = robot_fw.sim.state.pose.x
        assert wait_until(lambda: robot_fw.sim.state.pose.x > start_x + 0.02)
        assert "u=0.10 w=0.00" in robot_fw.serial_log
        assert robot_fw.receiver.bad_frames == 0


def test_the_handshake_puts_the_robot_at_rest_before_anything_else() -> None:
    """Issue 33, finding 3: a firmware with no watchdog holds its last command, so the first
    thing every robot hears on each command topic is its rest: zero velocity, LEDs off."""
    handler = Recorder(answer=drive_forward)
    with serving(handler) as server, firmware(server) as robot_fw:
        assert wait_until(lambda: any(m.linear.x > 0 for m in robot_fw.received_on("Control")))
        controls = robot_fw.received_on("Control")
        assert controls[0] == Twist()  # before the first command the handler sent
        assert [list(m.data) for m in robot_fw.received_on("Leds")] == [[0, 0, 0]]
        assert robot_fw.received_on("Buzzer") == []  # a note ends by itself: no rest to send


def test_a_stop_puts_the_robot_at_rest_before_the_tx_stop() -> None:
    handler = Recorder(answer=drive_forward)
    with serving(handler) as server, firmware(server, reconnect=False) as robot_fw:
        assert wait_until(lambda: any(m.linear.x > 0 for m in robot_fw.received_on("Control")))
        handler.answer = None
        (robot,) = handler.connected
        robot.stop()
        assert wait_until(lambda: robot_fw.tx_stops == 1)
        assert robot_fw.received_on("Control")[-1] == Twist()
        assert list(robot_fw.received_on("Leds")[-1].data) == [0, 0, 0]
        assert len(robot_fw.received_on("Leds")) == 2  # at the handshake and at the stop


def test_an_md5_mismatch_is_reported_with_both_sums() -> None:
    handler = Recorder()
    with serving(handler) as server, firmware(server, wrong_md5=frozenset({"Control"})):
        assert wait_until(lambda: handler.connected)
        (robot,) = handler.connected
        (problem,) = robot.problems
        assert Twist._md5sum in problem and WRONG_MD5 in problem
        assert ("robot-1", LogLevel.ERROR, problem) in handler.logs
        assert "Control" not in robot.topics
        with pytest.raises(TopicError, match="does not subscribe to 'Control'"):
            robot.send("Control", Twist())


def test_log_lines_reach_the_handler() -> None:
    handler = Recorder()
    with serving(handler) as server, firmware(server) as robot_fw:
        assert wait_until(lambda: handler.connected)
        robot_fw.loginfo("hello from the CrowBot")
        assert wait_until(
            lambda: ("robot-1", LogLevel.INFO, "hello from the CrowBot") in handler.logs
        )


def test_stop_sends_tx_stop_and_the_robot_stops_publishing() -> None:
    handler = Recorder()
    with serving(handler) as server, firmware(server, reconnect=False) as robot_fw:
        assert wait_until(lambda: handler.connected)
        (robot,) = handler.connected
        robot.stop()
        assert wait_until(lambda: robot_fw.tx_stops == 1 and not robot_fw.configured)
        assert wait_until(lambda: handler.disconnected and not robot_fw.connected)
        assert handler.disconnected[0][1] == "stopped by RoboDojo (tx stop sent)"
        assert server.robots() == [] and not robot.connected
        assert robot.close_reason == "stopped by RoboDojo (tx stop sent)"
        with pytest.raises(RobotDisconnected, match="the robot is disconnected"):
            robot.send("Control", Twist())


def test_stopping_the_server_sends_tx_stop_to_every_robot() -> None:
    handler = Recorder()
    server = RosserialServer(handler, host=LOOPBACK, port=0)
    server.start()
    with firmware(server) as first, firmware(server) as second:
        assert wait_until(lambda: len(handler.connected) == 2)
        server.stop()
        assert wait_until(lambda: first.tx_stops == second.tx_stops == 1)
        assert wait_until(lambda: len(handler.disconnected) == 2)
    server.stop()  # twice is fine


def test_the_host_requests_topics_again_when_time_requests_stop() -> None:
    handler = Recorder()
    with (
        serving(handler, sync_timeout_s=0.4, idle_timeout_s=30.0) as server,
        firmware(server, ask_time=False) as robot_fw,
    ):
        # The firmware answers every topic request with one time request (ros_lib's
        # requestSyncTime() in the negotiation) and then stays quiet about the time.
        assert wait_until(lambda: robot_fw.topic_requests >= 3, timeout_s=5.0)
        assert any(level is LogLevel.WARN and "sync" in line for _, level, line in handler.logs)
        assert len(handler.connected) == 1  # still the same connection


def test_the_firmware_drops_the_link_when_time_sync_is_not_answered() -> None:
    """A host that requests topics but never answers the time: after sync_timeout_s the
    firmware forgets its configuration and (as configured) closes the socket."""
    with socket.create_server((LOOPBACK, 0)) as listener:
        options = FirmwareOptions(sync_period_s=0.1, sync_timeout_s=0.5)
        robot_fw = CrowBotFirmware(LOOPBACK, listener.getsockname()[1], options)
        robot_fw.start()
        host, _ = listener.accept()
        with host:
            host.sendall(REQUEST_TOPICS_FRAME)
            assert robot_fw.wait_until(lambda: robot_fw.configured)
            assert robot_fw.wait_until(lambda: robot_fw.sync_losses == 1, timeout_s=3.0)
            received = read_until_closed(host, 3.0)
            assert not robot_fw.connected and not robot_fw.configured
            frames = FrameParser().feed(received)
            assert sum(f.topic_id == 10 for f in frames) >= 3  # it kept asking
        robot_fw.stop()


# ----------------------------------------------------------------------------- bad input
def test_bad_frames_are_dropped_and_counted_and_another_robot_is_served() -> None:
    handler = Recorder()
    with serving(handler) as server, firmware(server) as good, firmware(server, seed=1) as bad:
        assert wait_until(lambda: len(handler.connected) == 2)
        bad_robot = next(r for r in handler.connected if r.peer[1] == bad_port(bad))
        before = handler.count(other_id(handler, bad_robot))
        for _ in range(3):
            bad.send_bad_checksum()
            bad.send_bad_length()
            bad.send_oversized()
            bad.send_unknown_topic()
            bad.send_garbage(2000)
        assert wait_until(
            lambda: (
                bad_robot.drops["bad_checksum"] >= 3
                and bad_robot.drops["bad_length_checksum"] >= 3
                and bad_robot.drops["oversized"] >= 3
                and bad_robot.session.stats.unknown_topic_frames >= 3
            )
        )
        assert any("topic id 160" in p for p in bad_robot.problems)
        # Both robots keep streaming.
        bad_before = handler.count(bad_robot.id)
        assert wait_until(lambda: handler.count(bad_robot.id) > bad_before + 20)
        assert wait_until(lambda: handler.count(other_id(handler, bad_robot)) > before + 40)
        assert good.connected and bad.connected


def bad_port(robot_fw: CrowBotFirmware) -> int:
    assert robot_fw._sock is not None
    return robot_fw._sock.getsockname()[1]


def other_id(handler: Recorder, robot: RobotConnection) -> str:
    return next(r.id for r in handler.connected if r is not robot)


def test_a_firmware_that_corrupts_frames_still_gets_through() -> None:
    handler = Recorder()
    with serving(handler) as server, firmware(server, corrupt_every=3, garbage_bytes_per_tick=50):
        assert wait_until(lambda: handler.connected and handler.count("robot-1") >= 40)
        robot = handler.connected[0]
        assert robot.drops["bad_checksum"] >= 10


def test_a_garbage_flood_keeps_memory_flat_and_the_good_robot_served() -> None:
    handler = Recorder()
    process = psutil.Process()
    flood_s = 2.0
    with (
        serving(handler, max_bytes_per_s=256 * 1024) as server,
        firmware(server) as _good,
    ):
        assert wait_until(lambda: handler.connected)
        rss_before = process.memory_info().rss
        sent = 0
        buffered: list[int] = []
        with socket.create_connection((LOOPBACK, server.port)) as flood:
            flood.settimeout(0.05)
            assert wait_until(lambda: len(server.robots()) == 2)
            flooder = next(r for r in server.robots() if r is not handler.connected[0])
            good_before = handler.count("robot-1")
            noise = os.urandom(1 << 16) + b"\xff\xfe" * 4096  # random, then header candidates
            deadline = time.monotonic() + flood_s
            while time.monotonic() < deadline:
                with contextlib.suppress(TimeoutError, BlockingIOError):
                    sent += flood.send(noise)
                buffered.append(flooder.session.parser.buffered_bytes)
            good_during = handler.count("robot-1") - good_before
        rss_growth = process.memory_info().rss - rss_before
        print(
            f"flood: sent {sent} B, read {flooder.session.stats.bytes_in} B, paused "
            f"{flooder.reads_paused}x, drops {dict(flooder.drops)}, good robot "
            f"{good_during} messages, RSS +{rss_growth / 1e6:.1f} MB"
        )
        # 4 topics x 20 Hz for 2 s = 160; allow for a slow machine.
        assert good_during >= 80, good_during
        assert sent > 256 * 1024  # the flood filled the byte budget...
        assert flooder.reads_paused >= 1  # ...and reading paused at the limit
        assert flooder.session.stats.bytes_in <= 256 * 1024 * (flood_s + 2)
        # Sampled from this thread, possibly mid-feed: one read buffer on top of the held frame.
        bound = flooder.session.parser.max_buffered_bytes + server.limits.read_buffer_bytes
        assert max(buffered) <= bound
        assert rss_growth < 20 * 1024 * 1024, rss_growth
        assert handler.connected[0].state is SessionState.READY


def test_the_server_vouches_only_for_time_its_thread_was_reading() -> None:
    """`listened_until_s` (the silence watchdog's horizon) trails the clock by a beat or two,
    and does not move while the rosserial thread is kept from running: every Distance the
    robot sent before it has been dispatched."""
    handler = Recorder()
    with serving(handler) as server, firmware(server):
        assert wait_until(lambda: handler.count("robot-1", "Distance") >= 5)
        assert wait_until(lambda: server.listened_until_s is not None)
        assert time.monotonic() - server.listened_until_s < 0.5
        blocked = time.monotonic()
        server._call_on_loop(time.sleep, 0.4)  # a host too busy to schedule the thread
        time.sleep(0.2)
        assert server.listened_until_s < blocked + 0.05  # not vouched for while blocked
        sent_by = time.monotonic()  # the firmware went on publishing meanwhile
        assert wait_until(lambda: server.listened_until_s > sent_by)
        seen = handler.count("robot-1", "Distance")
        assert seen >= 5 + 4  # at 20 Hz, what came during the block was read before the beat


def test_a_silent_connection_is_closed() -> None:
    handler = Recorder()
    with (
        serving(handler, sync_timeout_s=0.2, idle_timeout_s=0.5) as server,
        socket.create_connection((LOOPBACK, server.port)) as silent,
    ):
        started = time.monotonic()
        received = read_until_closed(silent, 5.0)
        elapsed = time.monotonic() - started
        assert 0.4 < elapsed < 2.0, elapsed
        assert received.startswith(REQUEST_TOPICS_FRAME)
        assert received.count(REQUEST_TOPICS_FRAME) >= 2  # sync lost at 0.2 s: asked again
        assert wait_until(lambda: server.robots() == [])
        assert handler.connected == []  # never negotiated: no connect/disconnect callbacks


def test_a_half_open_frame_is_abandoned_and_the_connection_closed() -> None:
    with (
        serving(Recorder(), frame_timeout_s=0.2, idle_timeout_s=0.6) as server,
        socket.create_connection((LOOPBACK, server.port)) as peer,
    ):
        peer.sendall(bytes([0xFF, 0xFE, 0x00, 0x08, 0xF7, 0x7D, 0x00]) + bytes(100))
        assert wait_until(lambda: len(server.robots()) == 1)
        (robot,) = server.robots()
        assert wait_until(lambda: robot.drops["truncated"] == 1, timeout_s=2.0)
        assert robot.session.parser.buffered_bytes == 0
        read_until_closed(peer, 3.0)
        assert robot.state is SessionState.CLOSED and "sent nothing" in robot.session.close_reason


def test_a_robot_that_stops_reading_gets_the_newest_command_not_a_backlog() -> None:
    handler = Recorder()
    with serving(handler, max_write_buffer_bytes=16 * 1024) as server:
        peer = socket.socket()
        peer.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        peer.connect((LOOPBACK, server.port))
        with peer:
            peer.sendall(b"".join(negotiation_frames()))
            peer.sendall(ros_lib_frame(PUBLISHER_IDS["Distance"], Int32(1).serialize()))
            assert wait_until(lambda: handler.connected)
            (robot,) = handler.connected
            for index in range(40_000):  # ~2.2 MB of commands to a peer that never answers
                robot.send("Control", Twist(linear=Vector3(x=index / 40_000)))
            assert wait_until(lambda: robot.commands_replaced >= 40_000 - 2, timeout_s=10.0)
            assert robot.commands_waiting == 1
            transport = robot._transport
            assert transport is not None and transport.get_write_buffer_size() == 0
            # The peer speaks again: the newest command goes out, and nothing else did.
            peer.sendall(ros_lib_frame(PUBLISHER_IDS["Distance"], Int32(2).serialize()))
            assert wait_until(lambda: robot.commands_waiting == 0)
            peer.settimeout(2.0)
            received = bytearray()
            while len(received) < 2 * 56:
                received += peer.recv(4096)
            frames = [f for f in FrameParser(4096).feed(bytes(received)) if f.topic_id == 100]
            assert [Twist.deserialize(f.payload).linear.x for f in frames] == [
                0.0,
                39_999 / 40_000,
            ]


def test_connections_over_the_limit_are_refused() -> None:
    handler = Recorder()
    with (
        serving(handler, max_connections=2) as server,
        firmware(server),
        firmware(server),
    ):
        assert wait_until(lambda: len(handler.connected) == 2)
        with socket.create_connection((LOOPBACK, server.port)) as third:
            assert read_until_closed(third, 2.0) == b""  # closed at once, nothing sent
        assert len(server.robots()) == 2


def test_a_handler_that_raises_does_not_break_the_connection() -> None:
    class Broken(Recorder):
        def on_message(self, robot: RobotConnection, topic: str, message: Message) -> None:
            super().on_message(robot, topic, message)
            raise RuntimeError("a bug in the bridge")

    handler = Broken()
    with serving(handler) as server, firmware(server):
        assert wait_until(lambda: handler.count("robot-1") >= 20)
        assert server.handler_errors >= 20
        assert server.robots()[0].state is SessionState.READY


def test_a_busy_port_is_a_sentence() -> None:
    with socket.create_server((LOOPBACK, 0)) as taken:
        port = taken.getsockname()[1]
        server = RosserialServer(host=LOOPBACK, port=port)
        with pytest.raises(OSError, match=f"cannot listen on 127.0.0.1:{port}"):
            server.start()


def test_tx_stop_bytes_on_the_wire() -> None:
    with (
        serving(Recorder()) as server,
        socket.create_connection((LOOPBACK, server.port)) as peer,
    ):
        peer.sendall(b"".join(negotiation_frames()))
        assert wait_until(lambda: server.robots() and server.robots()[0].topics)
        server.robots()[0].stop()
        received = read_until_closed(peer, 3.0)
        assert received.startswith(REQUEST_TOPICS_FRAME) and received.endswith(TX_STOP_FRAME)


def test_a_groovy_era_firmware_is_explained_not_connected() -> None:
    handler = Recorder()
    with serving(handler) as server, firmware(server, protocol_version=0xFF) as robot_fw:
        # ros_lib sees our 0xFE, and (unconfigured) answers with a time request in its 0xFF.
        assert wait_until(lambda: robot_fw.receiver.version_mismatches >= 1)
        assert wait_until(lambda: any("Mismatched protocol version" in p for p in problems(server)))
        (problem,) = problems(server)
        assert "Rev 0 (rosserial 0.4 and earlier, ROS Groovy)" in problem
        assert handler.connected == [] and not robot_fw.configured


def problems(server: RosserialServer) -> list[str]:
    return [p for robot in server.robots() for p in robot.problems]


def test_a_robot_whose_wifi_drops_is_reported_disconnected() -> None:
    handler = Recorder()
    with serving(handler) as server, firmware(server) as robot_fw:
        assert wait_until(lambda: handler.connected)
        robot_fw._close()  # the link goes away
        assert wait_until(lambda: handler.disconnected)
        robot, reason = handler.disconnected[0]
        assert reason == "the robot closed the connection" and not robot.connected
        assert server.robots() == []
