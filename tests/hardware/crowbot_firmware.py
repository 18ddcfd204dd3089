"""A CrowBot BOLT firmware emulator that speaks rosserial over TCP the way ros_lib does.

It mirrors CrowBotROSV2.ino (joseVarelaAldas/ROS-Crowbot, the repository of
000_32b6074bbd2115c3.txt) running on ros_lib's ``NodeHandle_`` (rosserial_client node_handle.h)
with ``ArduinoTcpHardware`` (rosserial_arduino): it connects to the host's port 11411 and waits;
on the host's topic request (id 0) it asks for the time (id 10, a zeroed std_msgs/Time) and
advertises its publishers (ids 125.., on id 0) then its subscribers (ids 100.., on id 1), each
with its md5sum and a 512-byte buffer; once configured it publishes Distance, Button, Light and
Line every loop, asks for the time every SYNC_SECONDS * 500 ms = 2.5 s, and forgets its
configuration after SYNC_SECONDS * 2200 ms = 11 s without an answer, or on tx-stop (id 11).

Frames are built and parsed here independently of server.hardware.rosserial (ros_lib's own
byte state machine, ``MODE_FIRST_FF`` .. ``MODE_MSG_CHECKSUM``), so the host is tested against
a second implementation, not against itself. The robot is ``server.sim.Simulation("crowbot",
world)`` stepped in real time: Control drives it, sensor readings come from it.

Not like the real board: the loop runs at a fixed rate (the .ino loops as fast as pulseIn()
allows, with delay(1)), and between ticks it waits on the socket and handles a frame the moment
it arrives (the .ino sees it at its next spinOnce()), so latencies measured here are the host's
and the link's, not the firmware loop's. The sockets use TCP_NODELAY (lwIP on the ESP32 leaves
Nagle on unless setNoDelay(true)).

Misbehaviour on request (``FirmwareOptions``, ``send_*`` methods): wrong md5sums, another
protocol version, garbage, bad checksums, bad lengths, unknown topic ids, oversized frames, no
time requests, and dropping the connection when time sync is not answered.
"""

from __future__ import annotations

import contextlib
import gc
import random
import select
import socket
import struct
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

from sandbox.msgs.geometry_msgs import Twist
from sandbox.msgs.std_msgs import Bool, Int32, Int32MultiArray
from server.sim import Simulation, SimulationError

# ros_lib node_handle.h
SYNC_SECONDS = 5  # [s]
SYNC_PERIOD_S = SYNC_SECONDS * 500 / 1000  # [s] time requested this often once configured
SYNC_TIMEOUT_S = SYNC_SECONDS * 2200 / 1000  # [s] no answer for this long: configured_ = false
SERIAL_MSG_TIMEOUT_S = 0.020  # [s] a frame must complete within this after its first 0xFF
MAX_SUBSCRIBERS = 25  # ros.h default NodeHandle: 25 subscribers, 25 publishers
INPUT_SIZE = OUTPUT_SIZE = 512  # [bytes] buffers (paper Fig. 6: "buffer size is 512 bytes")
PROTOCOL_VER2 = 0xFE  # hydro and later
PROTOCOL_VER1 = 0xFF  # through groovy
ID_PUBLISHER, ID_SUBSCRIBER, ID_PARAMETER_REQUEST, ID_LOG, ID_TIME, ID_TX_STOP = 0, 1, 6, 7, 10, 11
LOG_INFO = 1  # rosserial_msgs/Log INFO

# CrowBotROSV2.ino, in the order it calls nh.advertise() and nh.subscribe().
PUBLISHERS = (
    ("Distance", Int32),
    ("Button", Bool),
    ("Light", Int32MultiArray),
    ("Line", Int32MultiArray),
)
SUBSCRIBERS = (("Control", Twist), ("Leds", Int32MultiArray), ("Buzzer", Bool))
PUBLISHER_IDS = {name: 100 + MAX_SUBSCRIBERS + i for i, (name, _) in enumerate(PUBLISHERS)}
SUBSCRIBER_IDS = {name: 100 + i for i, (name, _) in enumerate(SUBSCRIBERS)}
WRONG_MD5 = "0123456789abcdef0123456789abcdef"  # what a firmware with a changed .msg would send
UNKNOWN_TOPIC_ID = 160  # advertised by nobody


def ros_lib_frame(topic_id: int, payload: bytes, version: int = PROTOCOL_VER2) -> bytes:
    """NodeHandle_::publish(): 7 header bytes, the payload, 255 - sum(bytes 5..) % 256."""
    length = len(payload)
    header = bytes(
        (
            0xFF,
            version,
            length & 255,
            length >> 8,
            255 - ((length & 255) + (length >> 8)) % 256,
            topic_id & 255,
            topic_id >> 8,
        )
    )
    checksum = 255 - (sum(header[5:]) + sum(payload)) % 256
    return header + payload + bytes((checksum,))


def _ros_string(text: str) -> bytes:
    raw = text.encode()
    return struct.pack("<I", len(raw)) + raw


def topic_info_payload(
    topic_id: int, name: str, message_type: str, md5sum: str, buffer_size: int
) -> bytes:
    """rosserial_msgs::TopicInfo::serialize() as ros_lib's generated header writes it."""
    return (
        struct.pack("<H", topic_id)
        + _ros_string(name)
        + _ros_string(message_type)
        + _ros_string(md5sum)
        + struct.pack("<i", buffer_size)
    )


def log_payload(level: int, text: str) -> bytes:
    """rosserial_msgs::Log::serialize(): uint8 level, string msg."""
    return struct.pack("<B", level) + _ros_string(text)


def negotiation_frames(
    wrong_md5: frozenset[str] = frozenset(), version: int = PROTOCOL_VER2
) -> list[bytes]:
    """What the firmware writes on a topic request: requestSyncTime(), then negotiateTopics()."""
    frames = [ros_lib_frame(ID_TIME, bytes(8), version)]
    for name, message_class in PUBLISHERS:
        md5 = WRONG_MD5 if name in wrong_md5 else message_class._md5sum
        payload = topic_info_payload(
            PUBLISHER_IDS[name], name, message_class._type, md5, OUTPUT_SIZE
        )
        frames.append(ros_lib_frame(ID_PUBLISHER, payload, version))
    for name, message_class in SUBSCRIBERS:
        md5 = WRONG_MD5 if name in wrong_md5 else message_class._md5sum
        payload = topic_info_payload(
            SUBSCRIBER_IDS[name], name, message_class._type, md5, INPUT_SIZE
        )
        frames.append(ros_lib_frame(ID_SUBSCRIBER, payload, version))
    return frames


class RosLibReceiver:
    """NodeHandle_::spinOnce()'s byte-at-a-time state machine (the receiving half)."""

    FIRST_FF, PROTOCOL_VER, SIZE_L, SIZE_H, SIZE_CHECKSUM, TOPIC_L, TOPIC_H = range(7)
    MESSAGE, MSG_CHECKSUM = 7, 8

    def __init__(self, version: int = PROTOCOL_VER2, input_size: int = INPUT_SIZE) -> None:
        self.version = version
        self.input_size = input_size
        self.mode = self.FIRST_FF
        self.bytes = self.topic = self.checksum = 0
        self.message = bytearray()
        self.msg_timeout_s = 0.0
        self.version_mismatches = 0  # a 0xFF followed by another version byte
        self.bad_frames = 0  # length or message checksum wrong
        self.overflows = 0  # frames longer than message_in (a real board overruns its buffer)

    def feed(self, data: bytes, now_s: float) -> tuple[list[tuple[int, bytes]], bool]:
        """Frames completed by `data` as (topic id, payload), and whether a version mismatch
        happened (ros_lib then requests the time if unconfigured, to show its version)."""
        frames: list[tuple[int, bytes]] = []
        mismatch = False
        if self.mode != self.FIRST_FF and now_s > self.msg_timeout_s:
            self.mode = self.FIRST_FF  # "reset if message has timed out"
        for byte in data:
            self.checksum += byte
            mode = self.mode
            if mode == self.MESSAGE:
                self.message.append(byte)
                self.bytes -= 1
                if self.bytes == 0:
                    self.mode = self.MSG_CHECKSUM
            elif mode == self.FIRST_FF:
                if byte == 0xFF:
                    self.mode = self.PROTOCOL_VER
                    self.msg_timeout_s = now_s + SERIAL_MSG_TIMEOUT_S
            elif mode == self.PROTOCOL_VER:
                if byte == self.version:
                    self.mode = self.SIZE_L
                else:
                    self.mode = self.FIRST_FF
                    self.version_mismatches += 1
                    mismatch = True
            elif mode == self.SIZE_L:
                self.bytes = byte
                self.message = bytearray()
                self.checksum = byte
                self.mode = self.SIZE_H
            elif mode == self.SIZE_H:
                self.bytes += byte << 8
                self.mode = self.SIZE_CHECKSUM
            elif mode == self.SIZE_CHECKSUM:
                if self.checksum % 256 == 255 and self.bytes <= self.input_size:
                    self.mode = self.TOPIC_L
                else:
                    if self.checksum % 256 == 255:
                        self.overflows += 1
                    else:
                        self.bad_frames += 1
                    self.mode = self.FIRST_FF
            elif mode == self.TOPIC_L:
                self.topic = byte
                self.checksum = byte
                self.mode = self.TOPIC_H
            elif mode == self.TOPIC_H:
                self.topic += byte << 8
                self.mode = self.MESSAGE if self.bytes else self.MSG_CHECKSUM
            elif mode == self.MSG_CHECKSUM:
                self.mode = self.FIRST_FF
                if self.checksum % 256 == 255:
                    frames.append((self.topic, bytes(self.message)))
                else:
                    self.bad_frames += 1
        return frames, mismatch


@dataclass
class FirmwareOptions:
    """How the emulated firmware behaves; the defaults are the real CrowBot's."""

    rate_hz: float = 20.0  # [Hz] loop: sensors read and published
    world: str = "wall_approach"
    seed: int = 0
    protocol_version: int = PROTOCOL_VER2  # PROTOCOL_VER1 (0xFF) = a Groovy-era ros_lib
    wrong_md5: frozenset[str] = frozenset()  # topics advertised with WRONG_MD5
    ask_time: bool = True  # False: never requests the time (the host loses sync)
    sync_period_s: float = SYNC_PERIOD_S
    sync_timeout_s: float = SYNC_TIMEOUT_S
    # ros_lib itself only sets configured_ = false (stops publishing, keeps the socket). True
    # also closes the socket, like a firmware that re-runs initNode() when nh.connected() fails.
    drop_connection_on_sync_loss: bool = True
    reconnect: bool = False  # connect again after a drop (ArduinoTcpHardware::read() does)
    counter_distance: bool = False  # Distance = 1, 2, 3... instead of the ranger (benchmarks)
    publish: bool = True  # False: advertise only (a robot that never publishes)
    garbage_bytes_per_tick: int = 0  # random bytes written every loop
    corrupt_every: int = 0  # every n-th published frame carries a wrong checksum
    log_commands: bool = False  # nh.loginfo() a line for every command received


class CrowBotFirmware:
    """The emulator; ``start()`` connects (raises if it cannot), ``stop()`` ends it."""

    def __init__(self, host: str, port: int, options: FirmwareOptions | None = None) -> None:
        self.host, self.port = host, port
        self.options = options or FirmwareOptions()
        self.sim = Simulation("crowbot", self.options.world, seed=self.options.seed)
        self.configured = False  # ros_lib's configured_ (nh.connected())
        self.connected = False  # the TCP socket is open
        self.received: deque[tuple[float, str, object]] = deque(maxlen=100_000)
        self.distance_sent: deque[tuple[float, int]] = deque(maxlen=100_000)
        self.serial_log: deque[str] = deque(maxlen=1000)  # what the .ino prints on Serial
        self.topic_requests = self.time_requests = self.time_answers = self.tx_stops = 0
        self.sync_losses = self.disconnects = self.frames_published = 0
        self.host_time: tuple[int, int] | None = None  # (secs, nsecs) of the last answer
        self.receiver = RosLibReceiver(self.options.protocol_version)
        self._rng = random.Random(self.options.seed)
        self._sock: socket.socket | None = None
        self._write_lock = threading.Lock()
        self._stopping = threading.Event()
        self._thread: threading.Thread | None = None
        self._boot_s = time.monotonic()
        self._last_sync_time_s = self._last_sync_receive_s = self._rt_time_s = 0.0
        self._counter = 0
        self.error: BaseException | None = None
        # Called on the firmware thread with (topic, message, frame bytes) for every message
        # received on a subscribed topic (the command-line mode prints them).
        self.on_received: Callable[[str, object, int], None] | None = None

    # ------------------------------------------------------------------ control (any thread)
    def start(self) -> CrowBotFirmware:
        # The real board has a chip of its own; this one shares the test runner's interpreter,
        # where a full garbage collection after a few hundred tests stops every thread for
        # 150 ms and more (measured: 159 ms at 350k objects), which the host's 0.3 s silence
        # watchdog would blame on the robot. Objects alive now go out of the collector's reach.
        gc.freeze()
        self._connect()
        self._thread = threading.Thread(target=self._run, name="crowbot-firmware", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stopping.set()
        if self._thread is not None:
            self._thread.join(5.0)
        self._close()

    def __enter__(self) -> CrowBotFirmware:
        return self.start()

    def __exit__(self, *exc_info: object) -> None:
        self.stop()

    def wait_until(self, predicate: Callable[[], bool], timeout_s: float = 5.0) -> bool:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if predicate():
                return True
            time.sleep(0.005)
        return predicate()

    def received_on(self, topic: str) -> list[object]:
        return [message for _, name, message in list(self.received) if name == topic]

    def loginfo(self, text: str) -> None:
        """nh.loginfo(text)."""
        self._write(ros_lib_frame(ID_LOG, log_payload(LOG_INFO, text), self._version))

    def send_raw(self, data: bytes) -> None:
        self._write(data)

    def send_garbage(self, count: int) -> None:
        self._write(bytes(self._rng.randrange(256) for _ in range(count)))

    def send_bad_checksum(self) -> None:
        """A Distance frame whose last byte is off by one."""
        frame = bytearray(self._distance_frame(Int32(7)))
        frame[-1] = (frame[-1] + 1) % 256
        self._write(bytes(frame))

    def send_bad_length(self) -> None:
        """A Distance frame whose length checksum is wrong."""
        frame = bytearray(self._distance_frame(Int32(7)))
        frame[4] = (frame[4] + 1) % 256
        self._write(bytes(frame))

    def send_unknown_topic(self) -> None:
        """A good frame on a topic id the firmware never advertised."""
        self._write(ros_lib_frame(UNKNOWN_TOPIC_ID, Int32(7).serialize(), self._version))

    def send_oversized(self, payload_bytes: int = 4096) -> None:
        """A well-formed frame larger than any host limit (a board with huge buffers)."""
        self._write(ros_lib_frame(PUBLISHER_IDS["Distance"], bytes(payload_bytes), self._version))

    # ------------------------------------------------------------------ the firmware thread
    @property
    def _version(self) -> int:
        return self.options.protocol_version

    def _millis_s(self) -> float:
        return time.monotonic() - self._boot_s

    def _connect(self) -> None:
        sock = socket.create_connection((self.host, self.port), timeout=2.0)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        sock.settimeout(None)
        self._sock = sock
        self.connected = True
        self.receiver = RosLibReceiver(self.options.protocol_version)

    def _close(self) -> None:
        # The flags go down before the socket closes: a peer that sees the close (a test
        # reading until EOF) must find the firmware already disconnected, not race its thread.
        if self.connected:
            self.connected = False
            self.disconnects += 1
        self.configured = False
        with self._write_lock:
            sock, self._sock = self._sock, None
            if sock is not None:
                sock.close()

    def _write(self, data: bytes) -> None:
        with self._write_lock:
            if self._sock is None:
                return
            with contextlib.suppress(OSError):  # the read side notices and closes
                self._sock.sendall(data)

    def _run(self) -> None:
        try:
            while not self._stopping.is_set():
                if self._sock is None:
                    if not self.options.reconnect:
                        return
                    time.sleep(0.2)
                    try:
                        self._connect()
                    except OSError:
                        continue
                self._loop_connected()
        except BaseException as error:  # surfaced to tests through .error
            self.error = error
            raise

    def _loop_connected(self) -> None:
        period_s = 1.0 / self.options.rate_hz
        next_tick = time.monotonic()
        last_step = next_tick
        while not self._stopping.is_set() and self._sock is not None:
            now = time.monotonic()
            if now >= next_tick:
                self.sim.step(now - last_step)
                last_step = now
                self._loop_body()
                if not self._spin_timers():
                    return
                next_tick += period_s
                if next_tick < now:
                    next_tick = now + period_s
            sock = self._sock
            if sock is None:
                return
            try:
                timeout_s = max(0.0, next_tick - time.monotonic())
                readable, _, _ = select.select([sock], [], [], timeout_s)
            except (OSError, ValueError):  # closed by another thread (a test dropping the WiFi)
                readable = [sock]
            if readable:
                try:
                    data = sock.recv(4096)
                except OSError:
                    data = b""
                if not data:
                    self.serial_log.append("Not Connected")
                    self._close()
                    return
                self._spin_data(data)

    def _loop_body(self) -> None:
        """loop(): read the sensors, publish them if nh.connected()."""
        options = self.options
        if options.garbage_bytes_per_tick:
            self.send_garbage(options.garbage_bytes_per_tick)
        if not self.configured or not options.publish:
            return
        sim = self.sim
        if options.counter_distance:
            self._counter += 1
            distance = Int32(self._counter)
        else:
            distance = sim.read("Distance") or Int32(0)
        readings = {
            "Distance": distance,
            "Button": sim.read("Button") or Bool(False),
            "Light": sim.read("Light") or Int32MultiArray(data=[0, 0]),
            "Line": sim.read("Line") or Int32MultiArray(data=[0, 0]),
        }
        for name, _ in PUBLISHERS:
            frame = ros_lib_frame(PUBLISHER_IDS[name], readings[name].serialize(), self._version)
            self.frames_published += 1
            if options.corrupt_every and self.frames_published % options.corrupt_every == 0:
                frame = frame[:-1] + bytes(((frame[-1] + 1) % 256,))
            if name == "Distance":
                self.distance_sent.append((time.perf_counter(), distance.data))
            self._write(frame)

    def _distance_frame(self, message: Int32) -> bytes:
        return ros_lib_frame(PUBLISHER_IDS["Distance"], message.serialize(), self._version)

    def _spin_timers(self) -> bool:
        """The timer half of spinOnce(); False when the connection was dropped."""
        now = self._millis_s()
        if self.configured and now - self._last_sync_receive_s > self.options.sync_timeout_s:
            self.configured = False
            self.sync_losses += 1
            self.serial_log.append("Not Connected (time sync lost)")
            if self.options.drop_connection_on_sync_loss:
                self._close()
                return False
        if (
            self.configured
            and self.options.ask_time
            and now - self._last_sync_time_s > self.options.sync_period_s
        ):
            self._request_sync_time()
            self._last_sync_time_s = now
        return True

    def _spin_data(self, data: bytes) -> None:
        """The reading half of spinOnce(): handle every frame `data` completes."""
        now = self._millis_s()
        frames, mismatch = self.receiver.feed(data, now)
        if mismatch and not self.configured:
            self._request_sync_time()  # "send a msg back showing our protocol version"
        for topic_id, payload in frames:
            if topic_id == ID_PUBLISHER:
                self.topic_requests += 1
                self._request_sync_time()
                self._negotiate_topics()
                self._last_sync_time_s = self._last_sync_receive_s = now
            elif topic_id == ID_TIME:
                self._sync_time(payload, now)
            elif topic_id == ID_TX_STOP:
                self.tx_stops += 1
                self.configured = False
            elif topic_id == ID_PARAMETER_REQUEST:
                pass
            elif 100 <= topic_id < 100 + len(SUBSCRIBERS):
                self._subscriber_callback(*SUBSCRIBERS[topic_id - 100], payload)

    def _request_sync_time(self) -> None:
        self.time_requests += 1
        self._rt_time_s = self._millis_s()
        self._write(ros_lib_frame(ID_TIME, bytes(8), self._version))

    def _sync_time(self, payload: bytes, now: float) -> None:
        if len(payload) != 8:
            return
        secs, nsecs = struct.unpack("<II", payload)
        self.time_answers += 1
        self.host_time = (secs, nsecs)
        self._last_sync_receive_s = now

    def _negotiate_topics(self) -> None:
        for frame in negotiation_frames(self.options.wrong_md5, self._version)[1:]:
            self._write(frame)
        self.configured = True

    def _subscriber_callback(self, topic: str, message_class: type, payload: bytes) -> None:
        try:
            message = message_class.deserialize(payload)
        except ValueError as error:
            self.serial_log.append(f"{topic}: undecodable ({error})")
            return
        self.received.append((time.perf_counter(), topic, message))
        if self.on_received is not None:
            self.on_received(topic, message, len(payload) + 8)  # 7 header bytes + checksum
        if topic == "Control":
            self.serial_log.append(f"u={message.linear.x:.2f} w={message.angular.z:.2f}")
        try:
            self.sim.apply(topic, message)
        except (SimulationError, ValueError) as error:
            self.serial_log.append(f"{topic}: {error}")
        if self.options.log_commands:
            self.loginfo(f"received {topic}")


def main() -> None:
    """Run the emulator as its own process (a robot to SIGSTOP, or to put in a network
    namespace): one JSON line on stdout per command received, with its monotonic time [s] and
    frame size [bytes]; runs until stdin closes or the process is killed."""
    import argparse
    import json
    import sys

    parser = argparse.ArgumentParser(description=main.__doc__)
    parser.add_argument("host")
    parser.add_argument("port", type=int)
    parser.add_argument("--rate", type=float, default=20.0, help="[Hz] loop rate")
    parser.add_argument("--reconnect", action="store_true", help="connect again after a drop")
    args = parser.parse_args()
    options = FirmwareOptions(rate_hz=args.rate, reconnect=args.reconnect)
    robot = CrowBotFirmware(args.host, args.port, options)

    def report(topic: str, message: object, size: int) -> None:
        line = {"t": time.monotonic(), "topic": topic, "bytes": size}
        if topic == "Control":
            line["linear"] = message.linear.x  # type: ignore[attr-defined]
        elif topic == "Leds":
            line["leds"] = list(message.data)  # type: ignore[attr-defined]
        print(json.dumps(line), flush=True)

    robot.on_received = report
    with robot:
        print(json.dumps({"t": time.monotonic(), "topic": "connected", "bytes": 0}), flush=True)
        sys.stdin.read()  # the parent closes stdin to end us


if __name__ == "__main__":
    main()
