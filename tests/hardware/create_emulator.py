"""A fake iRobot Create on a pseudo-terminal, for testing `CreateDriver` without a robot.

`CreateEmulator` opens a pty (os.openpty); the driver opens `emulator.port` (the slave's path)
as it would /dev/ttyUSB0, and the emulator answers the Open Interface on the master end:

- modes OFF -> (Start) PASSIVE -> (Safe/Full) SAFE/FULL, (Stop) -> OFF; a command the current
  mode does not allow is read with its data bytes and ignored, as the robot does (in OFF every
  byte but Start is ignored);
- Drive Direct sets the wheel speeds (clamped to +-500 mm/s) and a differential-drive model
  integrates them; Passive and Off hold the wheels still;
- Stream / Pause-Resume Stream / Sensors: a frame of the requested packets every 15 ms;
- the wheel encoders count 508.8 per revolution of a 72 mm wheel and wrap at 16 bits (start
  them near 65535 with `encoder_start` to see the wrap);
- the world is a rectangular room: the 0.17 m round body stops at a wall, the wheels stall
  (their encoders stop too) and the bump switches close on the side that touches;
- a wheel drop (`drop_wheels()`) in Safe mode stops the wheels and falls back to Passive.

Test hooks: `frames_per_delivery` bunches frames as a USB adapter does, `inject(garbage)`
writes raw bytes onto the line, `go_silent()` stops every answer, `received` lists the commands
the robot understood with their data bytes, `pose()` is the truth.
Time is the wall clock: one physics step per 15 ms tick of time.monotonic.
"""

from __future__ import annotations

import contextlib
import math
import os
import select
import threading
import time
import tty
from dataclasses import dataclass

from server.hardware.create import oi

BODY_RADIUS_M = 0.17  # [m] Roomba 500 series, 34 cm across (as server/sim/robots/turtlebot.py)
WHEEL_BASE_M = 0.235  # [m] OI spec
METERS_PER_COUNT = math.pi * 0.072 / 508.8  # [m/count] OI spec: 72 mm wheel, 508.8 counts/rev
TICK_S = oi.STREAM_PERIOD_S  # [s] physics step and stream period
_CONTACT_M = 1e-6  # [m] closer to a wall than this is touching it (rounding of the stop)

# Data bytes that follow each opcode the emulator knows; None: the first data byte is a count
# of further bytes (Stream, Query List).
_DATA_BYTES: dict[int, int | None] = {
    oi.Opcode.START: 0,
    oi.Opcode.BAUD: 1,
    oi.Opcode.SAFE: 0,
    oi.Opcode.FULL: 0,
    oi.Opcode.DRIVE: 4,
    oi.Opcode.DRIVE_DIRECT: 4,
    oi.Opcode.SENSORS: 1,
    oi.Opcode.QUERY_LIST: None,
    oi.Opcode.STREAM: None,
    oi.Opcode.PAUSE_RESUME_STREAM: 1,
    oi.Opcode.STOP: 0,
}
# Modes in which each command is obeyed (OI spec, "Available in modes").
_ANY_ON = frozenset({oi.OIMode.PASSIVE, oi.OIMode.SAFE, oi.OIMode.FULL})
_DRIVING = frozenset({oi.OIMode.SAFE, oi.OIMode.FULL})
_ALLOWED_IN: dict[int, frozenset[oi.OIMode]] = {
    oi.Opcode.DRIVE: _DRIVING,
    oi.Opcode.DRIVE_DIRECT: _DRIVING,
}


@dataclass(frozen=True)
class Room:
    """An axis-aligned room [m]; the robot starts inside it."""

    min_x_m: float = -2.0
    max_x_m: float = 2.0
    min_y_m: float = -2.0
    max_y_m: float = 2.0


class CreateEmulator:
    """See module doc. Use as a context manager, or call `close()`."""

    def __init__(
        self,
        *,
        room: Room | None = None,
        start_pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
        encoder_start: tuple[int, int] = (0, 0),
        frames_per_delivery: int = 1,
    ) -> None:
        self.room = room or Room()
        self.x_m, self.y_m, self.yaw_rad = start_pose
        self.mode = oi.OIMode.OFF
        self.left_mm_s = 0
        self.right_mm_s = 0
        self._left_counts = float(encoder_start[0])  # cumulative, unwrapped
        self._right_counts = float(encoder_start[1])
        self._distance_mm = 0.0  # since the last report (packet 19)
        self._angle_deg = 0.0  # since the last report (packet 20)
        self._bumps = 0
        self._wheel_drops = 0
        self._stream_ids: tuple[int, ...] = ()
        self._streaming = False
        self._silent = False
        self.received: list[tuple[int, bytes]] = []
        self.frames_sent = 0
        # A USB-serial adapter holds bytes for its latency timer (FTDI: 16 ms) and hands them
        # over in bunches; frames_per_delivery > 1 writes that many frames at once.
        self.frames_per_delivery = frames_per_delivery
        self._held = bytearray()
        self._pending = bytearray()
        self._lock = threading.Lock()
        self._master_fd, self._slave_fd = os.openpty()
        tty.setraw(self._slave_fd)  # no echo, no newline translation before pyserial opens it
        os.set_blocking(self._master_fd, False)
        self.port = os.ttyname(self._slave_fd)
        self._running = True
        self._thread = threading.Thread(target=self._run, name="create-emulator", daemon=True)
        self._thread.start()

    # --- test hooks --------------------------------------------------------------------------

    def pose(self) -> tuple[float, float, float]:
        with self._lock:
            return self.x_m, self.y_m, self.yaw_rad

    def encoder_counts(self) -> tuple[int, int]:
        """What packets 43/44 report now."""
        with self._lock:
            return self._wrapped_counts()

    def commands(self, opcode: oi.Opcode) -> list[bytes]:
        """Data bytes of every accepted-or-ignored `opcode` command received, oldest first."""
        with self._lock:
            return [data for code, data in self.received if code == opcode]

    def inject(self, data: bytes) -> None:
        """Write raw bytes onto the line (between two frames)."""
        with self._lock:
            self._send(data)

    def go_silent(self) -> None:
        """Stop answering at all (a flat battery, a pulled cable)."""
        with self._lock:
            self._silent = True

    def speak_again(self) -> None:
        """Undo go_silent(): the stream comes back where it was."""
        with self._lock:
            self._silent = False

    def put_down(self) -> None:
        """Undo drop_wheels(): the wheels touch the floor again (the mode stays Passive)."""
        with self._lock:
            self._wheel_drops = 0

    def drop_wheels(self) -> None:
        """Lift the robot: both wheel drops close; in Safe mode it stops and goes Passive."""
        with self._lock:
            self._wheel_drops = oi.WHEEL_DROP_LEFT_BIT | oi.WHEEL_DROP_RIGHT_BIT
            if self.mode == oi.OIMode.SAFE:
                self._set_mode(oi.OIMode.PASSIVE)

    def close(self) -> None:
        """End the robot and both ends of the pty (a pulled cable, for a driver still open)."""
        if not self._running:
            return
        self._running = False
        self._thread.join()
        os.close(self._master_fd)
        os.close(self._slave_fd)

    def __enter__(self) -> CreateEmulator:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    # --- the robot ---------------------------------------------------------------------------

    def _run(self) -> None:
        next_tick = time.monotonic() + TICK_S
        while self._running:
            timeout = max(0.0, next_tick - time.monotonic())
            readable, _, _ = select.select([self._master_fd], [], [], timeout)
            if readable:
                try:
                    data = os.read(self._master_fd, 4096)
                except (BlockingIOError, OSError):
                    data = b""
                with self._lock:
                    for byte in data:
                        self._on_byte(byte)
            now = time.monotonic()
            if now >= next_tick:
                with self._lock:
                    self._tick()
                next_tick += TICK_S
                if now - next_tick > 10 * TICK_S:
                    next_tick = now + TICK_S  # the test machine stalled: do not replay it all

    def _send(self, data: bytes) -> None:
        if self._silent:
            return
        # Nobody reads: the bytes are lost, as on a real UART.
        with contextlib.suppress(BlockingIOError, OSError):
            os.write(self._master_fd, data)

    def _on_byte(self, byte: int) -> None:
        if self._silent:
            return
        self._pending.append(byte)
        opcode = self._pending[0]
        if opcode not in _DATA_BYTES:
            self._pending.clear()  # not a command the emulator knows: ignored
            return
        if self.mode == oi.OIMode.OFF and opcode != oi.Opcode.START:
            self._pending.clear()  # the OI only listens for Start
            return
        size = _DATA_BYTES[opcode]
        if size is None:
            if len(self._pending) < 2:
                return
            size = 1 + self._pending[1]
        if len(self._pending) < 1 + size:
            return
        data = bytes(self._pending[1:])
        self._pending.clear()
        self.received.append((opcode, data))
        if self.mode in _ALLOWED_IN.get(opcode, _ANY_ON) or opcode == oi.Opcode.START:
            self._execute(oi.Opcode(opcode), data)

    def _execute(self, opcode: oi.Opcode, data: bytes) -> None:
        if opcode == oi.Opcode.START:
            self._set_mode(oi.OIMode.PASSIVE)
        elif opcode == oi.Opcode.SAFE:
            self._set_mode(oi.OIMode.PASSIVE if self._wheel_drops else oi.OIMode.SAFE)
        elif opcode == oi.Opcode.FULL:
            self._set_mode(oi.OIMode.FULL)
        elif opcode == oi.Opcode.STOP:
            self._set_mode(oi.OIMode.OFF)
            self._streaming = False
        elif opcode == oi.Opcode.DRIVE_DIRECT:
            right = int.from_bytes(data[0:2], "big", signed=True)
            left = int.from_bytes(data[2:4], "big", signed=True)
            self.right_mm_s = max(-500, min(500, right))
            self.left_mm_s = max(-500, min(500, left))
        elif opcode == oi.Opcode.STREAM:
            self._stream_ids = tuple(i for i in data[1:] if i in oi.PACKETS)
            self._streaming = bool(self._stream_ids)
        elif opcode == oi.Opcode.PAUSE_RESUME_STREAM:
            self._streaming = bool(data[0]) and bool(self._stream_ids)
        elif opcode == oi.Opcode.SENSORS and data[0] in oi.PACKETS:
            self._send(oi.encode_packet_value(data[0], self._packet_value(data[0])))

    def _set_mode(self, mode: oi.OIMode) -> None:
        self.mode = mode
        if mode not in _DRIVING:
            self.left_mm_s = self.right_mm_s = 0

    def _wrapped_counts(self) -> tuple[int, int]:
        return math.floor(self._left_counts) & 0xFFFF, math.floor(self._right_counts) & 0xFFFF

    def _packet_value(self, packet_id: int) -> int:
        if packet_id == oi.BUMPS_WHEEL_DROPS:
            return self._bumps | self._wheel_drops
        if packet_id == oi.DISTANCE:
            value = max(-32768, min(32767, round(self._distance_mm)))
            self._distance_mm = 0.0
            return value
        if packet_id == oi.ANGLE:
            value = max(-32768, min(32767, round(self._angle_deg)))
            self._angle_deg = 0.0
            return value
        if packet_id == oi.OI_MODE:
            return int(self.mode)
        if packet_id == oi.REQUESTED_RIGHT_VELOCITY:
            return self.right_mm_s
        if packet_id == oi.REQUESTED_LEFT_VELOCITY:
            return self.left_mm_s
        left, right = self._wrapped_counts()
        if packet_id == oi.LEFT_ENCODER_COUNTS:
            return left
        if packet_id == oi.RIGHT_ENCODER_COUNTS:
            return right
        return 0  # no virtual wall, no cliff

    def _tick(self) -> None:
        self._move(TICK_S)
        if self._streaming:
            frame = oi.encode_stream_frame({i: self._packet_value(i) for i in self._stream_ids})
            self._held += frame
            self.frames_sent += 1
            if self.frames_sent % self.frames_per_delivery == 0:
                self._send(bytes(self._held))
                self._held.clear()

    def _walls(self) -> tuple[tuple[float, float, float], ...]:
        """(inward normal x, y, offset c) of each wall: inside the room, n . p >= c."""
        room = self.room
        return (
            (1.0, 0.0, room.min_x_m),
            (-1.0, 0.0, -room.max_x_m),
            (0.0, 1.0, room.min_y_m),
            (0.0, -1.0, -room.max_y_m),
        )

    def _clearance_m(self, wall: tuple[float, float, float]) -> float:
        nx, ny, offset = wall
        return nx * self.x_m + ny * self.y_m - offset - BODY_RADIUS_M

    def _move(self, dt_s: float) -> None:
        left_m = self.left_mm_s / 1000.0 * dt_s
        right_m = self.right_mm_s / 1000.0 * dt_s
        distance_m = 0.5 * (left_m + right_m)
        yaw_change = (right_m - left_m) / WHEEL_BASE_M
        heading = self.yaw_rad + 0.5 * yaw_change
        dx, dy = distance_m * math.cos(heading), distance_m * math.sin(heading)
        # A wall stops the body where it touches; the wheels stall there, so their encoders
        # count only the motion that happened (turning on the spot still works).
        fraction = 1.0
        for wall in self._walls():
            approach = wall[0] * dx + wall[1] * dy
            clearance = self._clearance_m(wall)
            if approach < 0.0 and clearance + approach < 0.0:
                fraction = min(fraction, max(0.0, clearance) / -approach)
        dx, dy, distance_m = dx * fraction, dy * fraction, distance_m * fraction
        self.x_m += dx
        self.y_m += dy
        self.yaw_rad = math.remainder(self.yaw_rad + yaw_change, 2.0 * math.pi)
        half_turn_m = 0.5 * yaw_change * WHEEL_BASE_M
        self._left_counts += (distance_m - half_turn_m) / METERS_PER_COUNT
        self._right_counts += (distance_m + half_turn_m) / METERS_PER_COUNT
        self._distance_mm += distance_m * 1000.0
        self._angle_deg += math.degrees(yaw_change)
        self._bumps = self._bump_bits()

    def _bump_bits(self) -> int:
        """Left/right switches from where the walls touch, in the robot's frame: ahead within
        10 degrees closes both (one shell on two switches), as server/sim/sensors/odometry.py
        decides it; a contact behind the axle closes none."""
        bits = 0
        for wall in self._walls():
            if self._clearance_m(wall) > _CONTACT_M:
                continue
            nx, ny, _ = wall
            bearing = math.remainder(math.atan2(-ny, -nx) - self.yaw_rad, 2.0 * math.pi)
            if abs(bearing) < math.radians(10.0):
                bits |= oi.BUMP_LEFT_BIT | oi.BUMP_RIGHT_BIT
            elif 0.0 < bearing <= math.pi / 2:
                bits |= oi.BUMP_LEFT_BIT
            elif -math.pi / 2 <= bearing <= 0.0:
                bits |= oi.BUMP_RIGHT_BIT
        return bits
