"""rosserial frames: encode one, and parse a byte stream into them. Pure: bytes in, frames out.

Wire format (rosserial wiki, "rosserial/Overview/Protocol"; rosserial_python SerialClient.py
``_send``/``run``; ros_lib node_handle.h ``publish``/``spinOnce``; facts collected in
shared/notes/protocols.md)::

    FF  FE  len_lo len_hi  len_chk  id_lo id_hi  payload...  chk
    len_chk = 255 - (len_lo + len_hi) % 256
    chk     = 255 - (id_lo + id_hi + sum(payload)) % 256

FF is the sync flag; the length counts payload bytes only.

The second byte is the protocol version: 0xFE since rosserial 0.5 (ROS Hydro); 0xFF was
rosserial 0.4 and earlier (Groovy). Topic ids below 100 are reserved (``TopicId``); a device
numbers its subscribers from 100 and its publishers from 100 + MAX_SUBSCRIBERS.

``FrameParser`` never raises on any input, resynchronizes on the next ``FF FE`` after garbage,
drops bad frames and counts them by ``DropReason``, and holds at most one incomplete frame.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass
from enum import IntEnum, StrEnum

from server.hardware.rosserial.limits import DEFAULT_LIMITS

SYNC_FLAG = 0xFF
PROTOCOL_VERSION = 0xFE  # "Rev 1": rosserial 0.5+ (Hydro and later, Noetic included)
PROTOCOL_VERSION_NAMES = {
    0xFF: "Rev 0 (rosserial 0.4 and earlier, ROS Groovy)",
    0xFE: "Rev 1 (rosserial 0.5+, ROS Hydro and later)",
    0xFD: "some future rosserial version",
}
HEADER_BYTES = 7  # sync, version, length (2), length checksum, topic id (2)
OVERHEAD_BYTES = HEADER_BYTES + 1  # and the trailing checksum
MAX_TOPIC_ID = 0xFFFF
MAX_WIRE_LENGTH = 0xFFFF  # the length field is a uint16
FIRST_DYNAMIC_TOPIC_ID = 100  # ids below are reserved for the protocol itself

_SYNC = bytes([SYNC_FLAG, PROTOCOL_VERSION])
# A sync flag followed by another release's version byte (both bytes inside skipped garbage).
_FOREIGN_VERSION = re.compile(rb"\xff(?=[\xff\xfd])")


class TopicId(IntEnum):
    """Reserved topic ids (rosserial_msgs/TopicInfo constants)."""

    PUBLISHER = 0  # device -> host: TopicInfo of a publisher; host -> device: request topics
    SUBSCRIBER = 1  # device -> host: TopicInfo of a subscriber
    SERVICE_SERVER = 2  # +0 publisher side, +1 subscriber side
    SERVICE_CLIENT = 4  # +0 publisher side, +1 subscriber side
    PARAMETER_REQUEST = 6
    LOG = 7
    TIME = 10  # device -> host: time request; host -> device: std_msgs/Time answer
    TX_STOP = 11  # host -> device: stop transmitting (the device forgets its configuration)


class DropReason(StrEnum):
    """Why the parser dropped bytes that started like a frame."""

    BAD_LENGTH_CHECKSUM = "bad_length_checksum"
    BAD_CHECKSUM = "bad_checksum"
    OVERSIZED = "oversized"
    WRONG_PROTOCOL_VERSION = "wrong_protocol_version"
    TRUNCATED = "truncated"  # started, then not completed within the frame timeout


@dataclass(frozen=True, slots=True)
class Frame:
    """One checked frame: its topic id and the serialized message it carries."""

    topic_id: int
    payload: bytes


def length_checksum(length: int) -> int:
    """The byte after the length: 255 - (len_lo + len_hi) % 256."""
    return 255 - ((length & 0xFF) + (length >> 8)) % 256


def payload_checksum(topic_id: int, payload: bytes | bytearray | memoryview) -> int:
    """The last byte: 255 - (id_lo + id_hi + sum(payload)) % 256."""
    return 255 - ((topic_id & 0xFF) + (topic_id >> 8) + sum(payload)) % 256


def encode_frame(topic_id: int, payload: bytes = b"") -> bytes:
    """The frame carrying `payload` on `topic_id`, as rosserial_python's ``_send`` builds it."""
    if not isinstance(topic_id, int) or not 0 <= topic_id <= MAX_TOPIC_ID:
        raise ValueError(f"a rosserial topic id is a uint16 (0..65535), got {topic_id!r}")
    length = len(payload)
    if length > MAX_WIRE_LENGTH:
        raise ValueError(
            f"a rosserial frame carries at most {MAX_WIRE_LENGTH} bytes, this payload has {length}"
        )
    return (
        bytes(
            (
                SYNC_FLAG,
                PROTOCOL_VERSION,
                length & 0xFF,
                length >> 8,
                length_checksum(length),
                topic_id & 0xFF,
                topic_id >> 8,
            )
        )
        + bytes(payload)
        + bytes((payload_checksum(topic_id, payload),))
    )


# The two frames the host sends with no payload (both given byte for byte in the notes).
REQUEST_TOPICS_FRAME = encode_frame(TopicId.PUBLISHER)  # ff fe 00 00 ff 00 00 ff
TX_STOP_FRAME = encode_frame(TopicId.TX_STOP)  # ff fe 00 00 ff 0b 00 f4


class FrameParser:
    """Incremental parser: ``feed(bytes) -> list[Frame]``; never raises, memory bounded.

    Bytes that are not part of a good frame are skipped (``skipped_bytes``). A header whose
    length checksum fails, a frame longer than `max_payload_bytes`, or one whose checksum fails
    is dropped and counted in ``drops``; scanning resumes at the byte after its sync flag, so a
    good frame hidden behind a bogus header is still found. ``FF`` followed by another release's
    version byte (``FF`` Groovy, ``FD``) counts as WRONG_PROTOCOL_VERSION and sets
    ``foreign_version``. At most one incomplete frame is kept (``buffered_bytes`` never exceeds
    ``max_buffered_bytes``); ``expire()`` abandons it when the stream has gone quiet.
    """

    def __init__(self, max_payload_bytes: int = DEFAULT_LIMITS.max_payload_bytes) -> None:
        if not isinstance(max_payload_bytes, int) or not 0 <= max_payload_bytes <= MAX_WIRE_LENGTH:
            raise ValueError(f"max_payload_bytes must be 0..65535, got {max_payload_bytes!r}")
        self.max_payload_bytes = max_payload_bytes
        self._buffer = bytearray()
        self.drops: Counter[DropReason] = Counter()
        self.skipped_bytes = 0
        self.frames = 0
        self.foreign_version: int | None = None  # the last other-release version byte seen

    @property
    def buffered_bytes(self) -> int:
        """Bytes held back as the start of a frame not yet complete."""
        return len(self._buffer)

    @property
    def max_buffered_bytes(self) -> int:
        """Upper bound of ``buffered_bytes`` between calls: the largest frame, less one byte."""
        return self.max_payload_bytes + OVERHEAD_BYTES - 1

    def feed(self, data: bytes | bytearray | memoryview) -> list[Frame]:
        """Parse `data` (appended to what is buffered); return the complete good frames."""
        self._buffer += data
        return self._scan()

    def expire(self) -> list[Frame]:
        """Abandon the incomplete frame held back (counted as TRUNCATED) and rescan the bytes
        after its sync flag; call when no byte arrived for the frame timeout."""
        if not self._buffer:
            return []
        if self._buffer.startswith(_SYNC):
            self.drops[DropReason.TRUNCATED] += 1
        self.skipped_bytes += 1
        del self._buffer[:1]
        return self._scan()

    def _scan(self) -> list[Frame]:
        buffer = self._buffer
        frames: list[Frame] = []
        position = 0
        while True:
            start = buffer.find(_SYNC, position)
            if start < 0:
                # Keep a trailing sync flag: its version byte has not arrived yet.
                keep = 1 if buffer.endswith(b"\xff") else 0
                self._skip(buffer, position, max(position, len(buffer) - keep))
                position = max(position, len(buffer) - keep)
                break
            self._skip(buffer, position, start)
            position = start
            if len(buffer) - start < HEADER_BYTES:
                break  # header incomplete
            length = buffer[start + 2] | buffer[start + 3] << 8
            if (buffer[start + 2] + buffer[start + 3] + buffer[start + 4]) % 256 != 255:
                self._drop(DropReason.BAD_LENGTH_CHECKSUM)
                position = start + 1
                continue
            if length > self.max_payload_bytes:
                self._drop(DropReason.OVERSIZED)
                position = start + 1
                continue
            end = start + OVERHEAD_BYTES + length
            if len(buffer) < end:
                break  # payload incomplete
            if sum(buffer[start + 5 : end]) % 256 != 255:
                self._drop(DropReason.BAD_CHECKSUM)
                position = start + 1
                continue
            topic_id = buffer[start + 5] | buffer[start + 6] << 8
            frames.append(Frame(topic_id, bytes(buffer[start + HEADER_BYTES : end - 1])))
            self.frames += 1
            position = end
        del buffer[:position]
        return frames

    def _drop(self, reason: DropReason) -> None:
        self.drops[reason] += 1
        self.skipped_bytes += 1  # the sync flag; the rest is rescanned

    def _skip(self, buffer: bytearray, start: int, end: int) -> None:
        if end <= start:
            return
        self.skipped_bytes += end - start
        foreign = len(_FOREIGN_VERSION.findall(buffer, start, end))
        if foreign:
            self.drops[DropReason.WRONG_PROTOCOL_VERSION] += foreign
            self.foreign_version = 0xFD if buffer.find(b"\xff\xfd", start, end) >= 0 else 0xFF
