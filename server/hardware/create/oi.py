"""The iRobot Open Interface (OI) on the wire: opcodes, sensor packets, command encoders and an
incremental sensor-stream parser. Pure: bytes in, bytes or values out; no serial port, no clock.

Sources: the iRobot Roomba 500 and Create 2 Open Interface specifications (the Roomba 531 of
003_4f92d1fa0a49ddae.txt section 3.1 speaks the Roomba 500 OI), summarised in
shared/notes/protocols.md. Multi-byte values are big-endian (high byte first).

Stream frame (OI "Stream", opcode 148), sent by the robot every 15 ms once requested::

    19 | n | id_1 data_1 ... id_k data_k | checksum

`n` counts the bytes between itself and the checksum; the checksum makes the 8-bit sum of every
byte of the frame, header and checksum included, equal to 0.
"""

from __future__ import annotations

import struct
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from enum import IntEnum

STREAM_HEADER = 19  # first byte of every stream frame
STREAM_PERIOD_S = 0.015  # [s] the robot sends one frame every 15 ms (OI spec, Stream)
MAX_WHEEL_MM_S = 500  # [mm/s] Drive Direct accepts -500..500 per wheel


class Opcode(IntEnum):
    """OI command opcodes (the first byte of every command); data bytes follow as noted."""

    START = 128  # -> Passive mode; must precede every other command
    BAUD = 129  # [baud code]
    SAFE = 131  # -> Safe mode: user control, cliff/wheel-drop/charger safety stays on
    FULL = 132  # -> Full mode: user control, every safety reaction off
    DRIVE = 137  # [velocity hi lo, radius hi lo], int16 mm/s and mm
    DRIVE_DIRECT = 145  # [right hi lo, left hi lo], int16 mm/s each
    SENSORS = 142  # [packet id]: one reply, no header, no checksum
    QUERY_LIST = 149  # [n, ids...]: one reply, the packets' data back to back
    STREAM = 148  # [n, ids...]: a frame every 15 ms until paused
    PAUSE_RESUME_STREAM = 150  # [0 = pause, 1 = resume]
    STOP = 173  # -> Off mode; the OI stops listening (Create 2 / Roomba 600 OI)


class OIMode(IntEnum):
    """OI modes as packet 35 reports them."""

    OFF = 0
    PASSIVE = 1
    SAFE = 2
    FULL = 3


@dataclass(frozen=True)
class PacketSpec:
    """One sensor packet: its id, how many data bytes and how to read them."""

    packet_id: int
    name: str
    size: int  # [bytes]
    signed: bool
    unit: str


# Sensor packets this package reads or the emulator serves.
# | id | name                  | bytes | signed | unit   | notes                                  |
# |----|-----------------------|-------|--------|--------|----------------------------------------|
# |  7 | bumps and wheel drops |   1   |   no   | bits   | bit 0 bump right, 1 bump left,         |
# |    |                       |       |        |        | 2 wheel drop right, 3 wheel drop left  |
# | 13 | virtual wall          |   1   |   no   | bool   | in the spec's Stream example           |
# | 19 | distance              |   2   |  yes   | mm     | since the last report, (left+right)/2  |
# | 20 | angle                 |   2   |  yes   | deg    | since the last report, ccw +           |
# | 29 | cliff front left sig. |   2   |   no   | 0-4095 | in the spec's Stream example           |
# | 35 | OI mode               |   1   |   no   | enum   | OIMode; Safe drops to Passive by itself|
# | 41 | requested right vel.  |   2   |  yes   | mm/s   | the last Drive Direct right wheel      |
# | 42 | requested left vel.   |   2   |  yes   | mm/s   | the last Drive Direct left wheel       |
# | 43 | left encoder counts   |   2   |   no   | counts | cumulative, rolls over at 16 bits      |
# | 44 | right encoder counts  |   2   |   no   | counts | cumulative, rolls over at 16 bits      |
# Encoder counts are read unsigned here (Roomba 500 spec: 0..65535); the Create 2 spec calls
# them signed. Both are the same 16-bit register, so a wrapping difference reads either right.
PACKETS: dict[int, PacketSpec] = {
    spec.packet_id: spec
    for spec in (
        PacketSpec(7, "bumps_wheel_drops", 1, False, "bits"),
        PacketSpec(13, "virtual_wall", 1, False, "bool"),
        PacketSpec(19, "distance", 2, True, "mm"),
        PacketSpec(20, "angle", 2, True, "deg"),
        PacketSpec(29, "cliff_front_left_signal", 2, False, "0-4095"),
        PacketSpec(35, "oi_mode", 1, False, "enum"),
        PacketSpec(41, "requested_right_velocity", 2, True, "mm/s"),
        PacketSpec(42, "requested_left_velocity", 2, True, "mm/s"),
        PacketSpec(43, "left_encoder_counts", 2, False, "counts"),
        PacketSpec(44, "right_encoder_counts", 2, False, "counts"),
    )
}
BUMPS_WHEEL_DROPS = 7
DISTANCE = 19
ANGLE = 20
OI_MODE = 35
REQUESTED_RIGHT_VELOCITY = 41
REQUESTED_LEFT_VELOCITY = 42
LEFT_ENCODER_COUNTS = 43
RIGHT_ENCODER_COUNTS = 44

BUMP_RIGHT_BIT = 0x01
BUMP_LEFT_BIT = 0x02
WHEEL_DROP_RIGHT_BIT = 0x04
WHEEL_DROP_LEFT_BIT = 0x08

_FORMATS = {(1, False): ">B", (1, True): ">b", (2, False): ">H", (2, True): ">h"}


def packet_spec(packet_id: int) -> PacketSpec:
    """The table entry for `packet_id`, or a ValueError that lists the known ones."""
    try:
        return PACKETS[packet_id]
    except KeyError:
        known = ", ".join(str(key) for key in sorted(PACKETS))
        raise ValueError(
            f"sensor packet {packet_id} is not in oi.PACKETS (known: {known})"
        ) from None


def encode_packet_value(packet_id: int, value: int) -> bytes:
    """`value` as packet `packet_id`'s data bytes (big-endian); ValueError when out of range."""
    spec = packet_spec(packet_id)
    try:
        return struct.pack(_FORMATS[spec.size, spec.signed], value)
    except struct.error:
        raise ValueError(f"{value} does not fit sensor packet {packet_id} ({spec.name})") from None


def decode_packet_value(packet_id: int, data: bytes) -> int:
    """Packet `packet_id`'s data bytes as an int."""
    spec = packet_spec(packet_id)
    return struct.unpack(_FORMATS[spec.size, spec.signed], data)[0]


# --- commands ----------------------------------------------------------------------------------


def clamp_wheel_mm_s(velocity_mm_s: float) -> int:
    """A wheel velocity rounded to whole mm/s and clamped to Drive Direct's -500..500."""
    return max(-MAX_WHEEL_MM_S, min(MAX_WHEEL_MM_S, round(velocity_mm_s)))


def encode_drive_direct(right_mm_s: float, left_mm_s: float) -> bytes:
    """Drive Direct (145): right wheel then left, int16 big-endian mm/s, each clamped to +-500."""
    return struct.pack(
        ">Bhh", Opcode.DRIVE_DIRECT, clamp_wheel_mm_s(right_mm_s), clamp_wheel_mm_s(left_mm_s)
    )


def encode_opcode(opcode: Opcode) -> bytes:
    """A command without data bytes (Start, Safe, Full, Stop)."""
    return bytes([Opcode(opcode)])


def encode_stream(packet_ids: Sequence[int]) -> bytes:
    """Stream (148): n, then the packet ids; every id must be in PACKETS."""
    for packet_id in packet_ids:
        packet_spec(packet_id)
    if not 0 < len(packet_ids) <= 255:
        raise ValueError(f"a stream asks for 1..255 packets, got {len(packet_ids)}")
    return bytes([Opcode.STREAM, len(packet_ids), *packet_ids])


def encode_pause_resume_stream(resume: bool) -> bytes:
    """Pause/Resume Stream (150): 0 pauses the stream, 1 resumes it."""
    return bytes([Opcode.PAUSE_RESUME_STREAM, 1 if resume else 0])


def encode_sensors(packet_id: int) -> bytes:
    """Sensors (142): ask once for one packet."""
    packet_spec(packet_id)
    return bytes([Opcode.SENSORS, packet_id])


# --- stream frames -----------------------------------------------------------------------------


def checksum(frame_without_checksum: bytes) -> int:
    """The byte that makes the 8-bit sum of the whole frame 0."""
    return -sum(frame_without_checksum) & 0xFF


def stream_payload_size(packet_ids: Iterable[int]) -> int:
    """`n` of a frame carrying these packets: one id byte plus the data per packet."""
    return sum(1 + packet_spec(packet_id).size for packet_id in packet_ids)


def encode_stream_frame(packets: Mapping[int, int]) -> bytes:
    """A stream frame with these packet values, in the mapping's order (as the robot sends them:
    in the order the Stream command asked)."""
    body = bytearray()
    for packet_id, value in packets.items():
        body.append(packet_id)
        body += encode_packet_value(packet_id, value)
    if len(body) > 255:
        raise ValueError(
            f"a stream frame carries at most 255 bytes, these packets need {len(body)}"
        )
    frame = bytes([STREAM_HEADER, len(body), *body])
    return frame + bytes([checksum(frame)])


def _decode_payload(payload: bytes) -> dict[int, int] | None:
    """The packets of a frame's payload, or None when it does not split into known packets."""
    packets: dict[int, int] = {}
    index = 0
    while index < len(payload):
        spec = PACKETS.get(payload[index])
        end = index + 1 + (spec.size if spec else 0)
        if spec is None or end > len(payload) or spec.packet_id in packets:
            return None
        packets[spec.packet_id] = decode_packet_value(spec.packet_id, payload[index + 1 : end])
        index = end
    return packets


@dataclass
class StreamStats:
    """What the parser has seen so far."""

    frames: int = 0  # good frames returned
    bad_frames: int = 0  # a header and a length that fit, but a wrong checksum or layout
    discarded_bytes: int = 0  # bytes skipped while looking for a frame (garbage, bad frames)


@dataclass
class StreamParser:
    """Turns the robot's byte stream into packet dicts, a chunk at a time, never raising.

    With `packet_ids` (what the driver asked the robot to stream) a frame must carry exactly
    those packets in that order, so `n` is known and a stray 19 in garbage is passed over at the
    next byte instead of swallowing up to 257 bytes of good frames. Without it any frame whose
    payload splits into known packets is accepted.

    On a bad checksum or layout the parser drops only the header byte and searches again from
    the next one: a real frame may start inside the bytes of a corrupt one.
    """

    packet_ids: tuple[int, ...] | None = None
    stats: StreamStats = field(default_factory=StreamStats)
    _buffer: bytearray = field(default_factory=bytearray, repr=False)

    def __post_init__(self) -> None:
        if self.packet_ids is not None:
            self.packet_ids = tuple(self.packet_ids)
            self._expected_n = stream_payload_size(self.packet_ids)
        else:
            self._expected_n = None

    def feed(self, data: bytes) -> list[dict[int, int]]:
        """Append `data`; return every complete good frame as {packet id: value}, oldest first."""
        self._buffer += data
        frames: list[dict[int, int]] = []
        buffer = self._buffer
        start = 0
        while True:
            header = buffer.find(STREAM_HEADER, start)
            if header < 0:
                self.stats.discarded_bytes += len(buffer) - start
                start = len(buffer)
                break
            self.stats.discarded_bytes += header - start
            start = header
            if len(buffer) - start < 2:
                break  # wait for n
            size = buffer[start + 1]
            if (self._expected_n is not None and size != self._expected_n) or size == 0:
                self.stats.discarded_bytes += 1
                start += 1
                continue
            end = start + 3 + size
            if len(buffer) < end:
                break  # wait for the rest of the frame
            frame = bytes(buffer[start:end])
            packets = _decode_payload(frame[2:-1]) if sum(frame) & 0xFF == 0 else None
            if packets is not None and self.packet_ids is not None:
                packets = packets if tuple(packets) == self.packet_ids else None
            if packets is None:
                self.stats.bad_frames += 1
                self.stats.discarded_bytes += 1
                start += 1
                continue
            self.stats.frames += 1
            frames.append(packets)
            start = end
        del buffer[:start]
        return frames
