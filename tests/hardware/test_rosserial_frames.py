"""frames.py: the rosserial wire format, byte for byte, and a parser that survives any input."""

from __future__ import annotations

import os

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sandbox.msgs.std_msgs import Int32
from server.hardware.rosserial.frames import (
    OVERHEAD_BYTES,
    REQUEST_TOPICS_FRAME,
    TX_STOP_FRAME,
    DropReason,
    Frame,
    FrameParser,
    TopicId,
    encode_frame,
    length_checksum,
    payload_checksum,
)
from server.hardware.rosserial.messages import Log, TopicInfo
from tests.hardware.crowbot_firmware import (
    PUBLISHER_IDS,
    WRONG_MD5,
    log_payload,
    negotiation_frames,
    ros_lib_frame,
    topic_info_payload,
)

MAX_PAYLOAD = 64  # small parser limit in the fuzz tests, so oversized headers are common


def good_frames() -> st.SearchStrategy[Frame]:
    return st.builds(
        Frame,
        topic_id=st.integers(0, 0xFFFF),
        payload=st.binary(max_size=MAX_PAYLOAD),
    )


# ----------------------------------------------------------------------------- known bytes
def test_the_two_host_frames_are_the_bytes_of_the_protocol_notes() -> None:
    assert bytes.fromhex("ff fe 00 00 ff 00 00 ff") == REQUEST_TOPICS_FRAME
    assert bytes.fromhex("ff fe 00 00 ff 0b 00 f4") == TX_STOP_FRAME


def test_an_int32_frame_computed_by_hand_from_the_spec() -> None:
    # std_msgs/Int32 data=42 on the CrowBot's first publisher id 125 (100 + MAX_SUBSCRIBERS 25).
    payload = bytes([42, 0, 0, 0])  # int32 little-endian
    length_lo, length_hi = 4, 0
    length_check = 255 - (length_lo + length_hi) % 256  # 251 = 0xfb
    topic_lo, topic_hi = 125, 0  # 0x7d 0x00
    check = 255 - (topic_lo + topic_hi + 42 + 0 + 0 + 0) % 256  # 255 - 167 = 88 = 0x58
    expected = bytes(
        [0xFF, 0xFE, length_lo, length_hi, length_check, topic_lo, topic_hi, *payload, check]
    )
    assert expected == bytes.fromhex("ff fe 04 00 fb 7d 00 2a 00 00 00 58")
    assert encode_frame(125, Int32(42).serialize()) == expected
    assert ros_lib_frame(125, payload) == expected  # the emulator's own encoder agrees
    assert FrameParser().feed(expected) == [Frame(125, payload)]


def test_checksums_on_a_two_byte_length_and_topic_id() -> None:
    assert length_checksum(0x0201) == 255 - (0x01 + 0x02)
    assert length_checksum(0xFFFF) == 255 - (0xFF + 0xFF) % 256
    assert payload_checksum(0x0102, b"\x10\x20") == 255 - (0x02 + 0x01 + 0x10 + 0x20)


def test_encode_refuses_what_the_wire_cannot_carry() -> None:
    with pytest.raises(ValueError, match="uint16"):
        encode_frame(70_000, b"")
    with pytest.raises(ValueError, match="at most 65535 bytes"):
        encode_frame(125, bytes(70_000))


def test_rosserial_msgs_md5sums_match_ros_libs_generated_headers() -> None:
    # rosserial_msgs/TopicInfo.h and Log.h getMD5() of ros_lib (noetic).
    assert TopicInfo._md5sum == "0ad51f88fc44892f8c10684077646005"
    assert Log._md5sum == "11abd731c25933261cd6183bd12d6295"
    assert TopicInfo.ID_TX_STOP == TopicId.TX_STOP == 11
    assert (TopicInfo.ID_SERVICE_CLIENT, TopicInfo.ID_PARAMETER_REQUEST) == (4, 6)


def test_topic_info_and_log_decode_what_ros_lib_writes() -> None:
    payload = topic_info_payload(125, "Distance", "std_msgs/Int32", Int32._md5sum, 512)
    info = TopicInfo.deserialize(payload)
    assert (info.topic_id, info.topic_name) == (125, "Distance")
    assert info.message_type == "std_msgs/Int32"
    assert (info.md5sum, info.buffer_size) == (Int32._md5sum, 512)
    assert info.serialize() == payload
    log = Log.deserialize(log_payload(2, "battery low"))
    assert (log.level, log.msg) == (Log.WARN, "battery low")


# ----------------------------------------------------------------------------- parser
def test_a_negotiation_split_at_every_byte_parses_the_same() -> None:
    stream = b"".join(negotiation_frames())
    whole = FrameParser().feed(stream)
    assert [f.topic_id for f in whole] == [10, 0, 0, 0, 0, 1, 1, 1]
    for cut in range(len(stream)):
        parser = FrameParser()
        assert parser.feed(stream[:cut]) + parser.feed(stream[cut:]) == whole
    byte_by_byte = FrameParser()
    assert [f for b in stream for f in byte_by_byte.feed(bytes([b]))] == whole


def test_bad_frames_are_dropped_counted_and_the_next_good_one_is_found() -> None:
    good = encode_frame(125, Int32(5).serialize())
    bad_length = bytearray(good)
    bad_length[4] ^= 0x01
    bad_checksum = bytearray(good)
    bad_checksum[-1] ^= 0x01
    oversized = encode_frame(125, bytes(MAX_PAYLOAD + 1))
    groovy = b"\xff\xff" + good[2:]  # a Groovy-era client's sync bytes
    parser = FrameParser(MAX_PAYLOAD)
    frames = parser.feed(bytes(bad_length) + good + bytes(bad_checksum) + oversized + groovy + good)
    assert frames == [Frame(125, Int32(5).serialize())] * 2
    assert parser.drops == {
        DropReason.BAD_LENGTH_CHECKSUM: 1,
        DropReason.BAD_CHECKSUM: 1,
        DropReason.OVERSIZED: 1,
        DropReason.WRONG_PROTOCOL_VERSION: 1,
    }
    assert parser.foreign_version == 0xFF
    assert parser.buffered_bytes == 0


def test_a_good_frame_behind_a_bogus_header_is_found_once_the_bogus_frame_fails() -> None:
    good = encode_frame(7, log_payload(1, "hi"))
    bogus_header = bytes([0xFF, 0xFE, 40, 0, 255 - 40, 0x7D, 0x00])  # claims 40 bytes
    parser = FrameParser()
    assert parser.feed(bogus_header + good) == []  # waiting for the 40 bytes
    assert parser.feed(bytes(40)) == [Frame(7, log_payload(1, "hi"))]
    assert parser.drops[DropReason.BAD_CHECKSUM] == 1


def test_expire_abandons_a_stalled_frame_and_rescans_behind_it() -> None:
    good = encode_frame(10, bytes(8))
    parser = FrameParser()
    assert parser.feed(bytes([0xFF, 0xFE, 200, 0, 255 - 200, 0x7D, 0x00]) + good) == []
    assert parser.expire() == [Frame(10, bytes(8))]
    assert parser.drops[DropReason.TRUNCATED] == 1
    assert parser.buffered_bytes == 0
    assert parser.expire() == []


def test_a_megabyte_of_random_bytes_leaves_the_buffer_bounded() -> None:
    parser = FrameParser()
    noise = os.urandom(1 << 20)
    frame_bytes = 0
    for offset in range(0, len(noise), 4096):
        frames = parser.feed(noise[offset : offset + 4096])
        frame_bytes += sum(OVERHEAD_BYTES + len(f.payload) for f in frames)
        assert parser.buffered_bytes <= parser.max_buffered_bytes
    assert frame_bytes + parser.skipped_bytes + parser.buffered_bytes == len(noise)
    tail = parser.feed(bytes(parser.max_buffered_bytes) + REQUEST_TOPICS_FRAME)
    assert tail[-1] == Frame(0, b"")  # the stream carries on


@settings(max_examples=300, deadline=None)
@given(frame=good_frames(), cut=st.integers(0, 200))
def test_round_trip_any_frame_split_anywhere(frame: Frame, cut: int) -> None:
    data = encode_frame(frame.topic_id, frame.payload)
    parser = FrameParser(MAX_PAYLOAD)
    assert parser.feed(data[:cut]) + parser.feed(data[cut:]) == [frame]
    assert parser.skipped_bytes == 0 and not parser.drops


@settings(max_examples=500, deadline=None)
@given(chunks=st.lists(st.binary(max_size=300), max_size=20))
def test_the_parser_never_raises_and_accounts_for_every_byte(chunks: list[bytes]) -> None:
    parser = FrameParser(MAX_PAYLOAD)
    frame_bytes = 0
    for chunk in chunks:
        frames = parser.feed(chunk)
        frame_bytes += sum(OVERHEAD_BYTES + len(f.payload) for f in frames)
        assert parser.buffered_bytes <= parser.max_buffered_bytes
    fed = sum(map(len, chunks))
    assert frame_bytes + parser.skipped_bytes + parser.buffered_bytes == fed
    while parser.buffered_bytes:  # expiring everything accounts for the rest
        frame_bytes += sum(OVERHEAD_BYTES + len(f.payload) for f in parser.expire())
    assert frame_bytes + parser.skipped_bytes == fed


@settings(max_examples=500, deadline=None)
@given(garbage=st.binary(max_size=200), frames=st.lists(good_frames(), min_size=1, max_size=4))
def test_resyncs_to_the_good_frames_after_garbage(garbage: bytes, frames: list[Frame]) -> None:
    """Garbage, then good frames, then enough quiet filler (no 0xFF) to close any bogus frame
    the garbage opened: every good frame comes out, in order, after whatever the garbage held."""
    stream = b"".join(encode_frame(f.topic_id, f.payload) for f in frames)
    filler = bytes(MAX_PAYLOAD + OVERHEAD_BYTES)
    parser = FrameParser(MAX_PAYLOAD)
    out = parser.feed(garbage) + parser.feed(stream) + parser.feed(filler)
    assert out[len(out) - len(frames) :] == frames
    assert parser.buffered_bytes == 0


@settings(max_examples=200, deadline=None)
@given(frames=st.lists(good_frames(), max_size=5), flips=st.lists(st.integers(0, 10_000)))
def test_corrupted_frames_are_counted_never_raise(frames: list[Frame], flips: list[int]) -> None:
    stream = bytearray(b"".join(encode_frame(f.topic_id, f.payload) for f in frames))
    for flip in flips:
        if stream:
            stream[flip % len(stream)] ^= 1 << (flip % 8)
    parser = FrameParser(MAX_PAYLOAD)
    out = parser.feed(bytes(stream)) + parser.expire()
    assert len(out) <= len(frames) + len(flips)
    assert parser.buffered_bytes <= parser.max_buffered_bytes


def test_wrong_md5_negotiation_frames_still_parse() -> None:
    frames = FrameParser().feed(b"".join(negotiation_frames(frozenset({"Distance"}))))
    infos = [TopicInfo.deserialize(f.payload) for f in frames if f.topic_id in (0, 1)]
    assert {i.topic_name: i.md5sum for i in infos}["Distance"] == WRONG_MD5
    assert {i.topic_name: i.topic_id for i in infos}["Distance"] == PUBLISHER_IDS["Distance"]
