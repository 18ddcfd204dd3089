"""server.hardware.create.oi: command bytes computed here from the OI spec, stream frames in and
out, and a parser that garbage cannot crash or derail."""

from __future__ import annotations

import itertools

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from server.hardware.create import oi

DRIVER_PACKETS = (7, 35, 43, 44)


def be16(value: int) -> list[int]:
    """Two's-complement big-endian bytes, as the spec writes a 16-bit value: high byte first."""
    raw = value & 0xFFFF
    return [raw >> 8, raw & 0xFF]


def test_opcodes_are_the_spec_numbers():
    assert oi.Opcode.START == 128
    assert oi.Opcode.SAFE == 131
    assert oi.Opcode.FULL == 132
    assert oi.Opcode.DRIVE_DIRECT == 145
    assert oi.Opcode.SENSORS == 142
    assert oi.Opcode.STREAM == 148
    assert oi.Opcode.PAUSE_RESUME_STREAM == 150
    assert oi.Opcode.STOP == 173


def test_packet_table_sizes_and_signedness():
    expected = {7: (1, False), 19: (2, True), 20: (2, True), 35: (1, False), 43: (2, False)}
    expected[44] = (2, False)
    for packet_id, (size, signed) in expected.items():
        spec = oi.PACKETS[packet_id]
        assert (spec.size, spec.signed) == (size, signed), spec


@pytest.mark.parametrize(
    ("right", "left"), [(0, 0), (200, 200), (200, -200), (-1, 1), (500, -500), (-32, 255)]
)
def test_drive_direct_is_right_then_left_big_endian(right, left):
    assert oi.encode_drive_direct(right, left) == bytes([145, *be16(right), *be16(left)])


def test_drive_direct_clamps_to_500_mm_s():
    assert oi.encode_drive_direct(600, -9000) == bytes([145, 0x01, 0xF4, 0xFE, 0x0C])
    assert oi.encode_drive_direct(1e9, -1e9) == bytes([145, *be16(500), *be16(-500)])


def test_drive_direct_rounds_to_whole_mm_s():
    assert oi.encode_drive_direct(199.6, -0.4) == bytes([145, *be16(200), *be16(0)])


def test_mode_stream_and_pause_commands():
    assert oi.encode_opcode(oi.Opcode.START) == b"\x80"
    assert oi.encode_opcode(oi.Opcode.SAFE) == b"\x83"
    assert oi.encode_opcode(oi.Opcode.FULL) == b"\x84"
    assert oi.encode_opcode(oi.Opcode.STOP) == b"\xad"
    assert oi.encode_stream(DRIVER_PACKETS) == bytes([148, 4, 7, 35, 43, 44])
    assert oi.encode_pause_resume_stream(resume=False) == bytes([150, 0])
    assert oi.encode_pause_resume_stream(resume=True) == bytes([150, 1])
    assert oi.encode_sensors(7) == bytes([142, 7])


def test_stream_of_an_unknown_packet_says_which_are_known():
    with pytest.raises(ValueError, match=r"sensor packet 99 is not in oi\.PACKETS \(known: 7, "):
        oi.encode_stream([7, 99])


def test_the_specs_own_stream_frame_example():
    # OI spec, Stream: packets 29 (value 0x0219 = 537) and 13 (0) -> 19 5 29 2 25 13 0 163.
    frame = bytes([19, 5, 29, 2, 25, 13, 0, 163])
    assert oi.encode_stream_frame({29: 537, 13: 0}) == frame
    assert oi.StreamParser().feed(frame) == [{29: 537, 13: 0}]


def test_frame_bytes_computed_by_hand():
    body = [7, 0b11, 35, 2, 43, *be16(65535), 44, *be16(258)]
    head = [19, len(body), *body]
    frame = bytes([*head, (256 - sum(head) % 256) % 256])
    assert sum(frame) % 256 == 0
    assert oi.encode_stream_frame({7: 3, 35: 2, 43: 65535, 44: 258}) == frame
    parser = oi.StreamParser(packet_ids=DRIVER_PACKETS)
    assert parser.feed(frame) == [{7: 3, 35: 2, 43: 65535, 44: 258}]


def test_signed_packets_decode_negative():
    frame = oi.encode_stream_frame({19: -12, 20: -90})
    assert frame[2:8] == bytes([19, 0xFF, 0xF4, 20, 0xFF, 0xA6])
    assert oi.StreamParser().feed(frame) == [{19: -12, 20: -90}]


def test_values_outside_a_packet_are_refused():
    with pytest.raises(ValueError, match="does not fit sensor packet 7"):
        oi.encode_stream_frame({7: 256})


def test_bad_checksum_is_counted_and_the_next_frame_still_parses():
    good = oi.encode_stream_frame({7: 1, 35: 2, 43: 10, 44: 20})
    bad = bytearray(good)
    bad[-1] ^= 0x01
    parser = oi.StreamParser(packet_ids=DRIVER_PACKETS)
    assert parser.feed(bytes(bad) + good) == [{7: 1, 35: 2, 43: 10, 44: 20}]
    assert parser.stats.bad_frames == 1
    assert parser.stats.frames == 1


def test_a_frame_of_other_packets_is_bad_when_the_layout_is_known():
    other = oi.encode_stream_frame({7: 1, 35: 2, 44: 10, 43: 20})  # same size, wrong order
    parser = oi.StreamParser(packet_ids=DRIVER_PACKETS)
    assert parser.feed(other) == []
    assert parser.stats.bad_frames == 1


def test_garbage_is_discarded_byte_for_byte():
    good = oi.encode_stream_frame({7: 0, 35: 2, 43: 1, 44: 2})
    garbage = bytes([0, 255, 19, 200, 19, 10, 1, 2, 3])
    parser = oi.StreamParser(packet_ids=DRIVER_PACKETS)
    assert parser.feed(garbage + good + garbage + good) == [{7: 0, 35: 2, 43: 1, 44: 2}] * 2
    parser.feed(good)
    assert parser.stats.discarded_bytes == 2 * len(garbage)


# --- properties --------------------------------------------------------------------------------

driver_values = st.fixed_dictionaries(
    {
        7: st.integers(0, 255),
        35: st.integers(0, 3),
        43: st.integers(0, 65535),
        44: st.integers(0, 65535),
    }
).map(lambda values: {packet_id: values[packet_id] for packet_id in DRIVER_PACKETS})


def chunked(data: bytes, cuts: list[int]) -> list[bytes]:
    points = sorted({cut % (len(data) + 1) for cut in cuts})
    edges = [0, *points, len(data)]
    return [data[a:b] for a, b in itertools.pairwise(edges)]


@settings(max_examples=300)
@given(data=st.binary(max_size=2000), cuts=st.lists(st.integers(0, 4000), max_size=20))
def test_any_bytes_in_any_chunks_never_raise(data, cuts):
    for packet_ids in (DRIVER_PACKETS, None):
        parser = oi.StreamParser(packet_ids=packet_ids)
        frames = []
        for chunk in chunked(data, cuts):
            frames += parser.feed(chunk)
        assert parser.stats.frames == len(frames)
        assert parser.stats.discarded_bytes <= len(data)
        assert len(parser._buffer) <= 3 + 255


@given(values=st.lists(driver_values, min_size=1, max_size=8), cuts=st.lists(st.integers()))
def test_round_trip_in_any_chunks(values, cuts):
    stream = b"".join(oi.encode_stream_frame(v) for v in values)
    parser = oi.StreamParser(packet_ids=DRIVER_PACKETS)
    frames = []
    for chunk in chunked(stream, cuts):
        frames += parser.feed(chunk)
    assert frames == values
    assert parser.stats.bad_frames == parser.stats.discarded_bytes == 0


@given(
    garbage=st.lists(st.binary(max_size=64).map(lambda b: b.replace(b"\x13", b"\x14")), max_size=5),
    values=st.lists(driver_values, min_size=1, max_size=5),
)
def test_resynchronizes_after_garbage_between_frames(garbage, values):
    # Garbage without a header byte cannot hide a frame; every frame after it must come through.
    stream = b""
    for index, value in enumerate(values):
        stream += (garbage[index] if index < len(garbage) else b"") + oi.encode_stream_frame(value)
    parser = oi.StreamParser(packet_ids=DRIVER_PACKETS)
    assert parser.feed(stream) == values
    assert parser.stats.discarded_bytes == sum(len(g) for g in garbage[: len(values)])


@given(
    values=st.lists(driver_values, min_size=3, max_size=6),
    victim=st.integers(0, 5),
    offset=st.integers(0, 12),
    flip=st.integers(1, 255),
)
def test_one_corrupted_byte_costs_at_most_its_own_frame(values, victim, offset, flip):
    frames = [bytearray(oi.encode_stream_frame(v)) for v in values]
    victim %= len(values)
    frames[victim][offset] ^= flip
    parser = oi.StreamParser(packet_ids=DRIVER_PACKETS)
    got = parser.feed(b"".join(frames))
    # A flipped byte never leaves a frame's checksum right, and with the layout known (ids 7,
    # 35, 43, 44 at fixed places) no header found inside the wreck can reach into the next
    # frame and still fit: exactly the victim is lost.
    assert got == values[:victim] + values[victim + 1 :]
    assert parser.stats.bad_frames <= 1
