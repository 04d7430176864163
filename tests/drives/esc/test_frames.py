"""The EtherCAT frame codec (ETG.1000.4 clause 5) and the lean walker the chain uses."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.drives.esc.frames import (
    ETH_HEADER_LEN,
    MAX_ECAT_LEN,
    MIN_ETH_FRAME,
    Datagram,
    FrameError,
    decode_frame,
    encode_frame,
    walk,
)
from gtecat.eni.ethercat import Command
from tests.conftest import examples

datagrams = st.builds(
    Datagram,
    command=st.integers(0, 14),
    adp=st.integers(0, 0xFFFF),
    ado=st.integers(0, 0xFFFF),
    data=st.binary(max_size=200),
    index=st.integers(0, 0xFF),
    wkc=st.integers(0, 0xFFFF),
    irq=st.integers(0, 0xFFFF),
    circulating=st.booleans(),
)
frames = st.lists(datagrams, min_size=1, max_size=6)


def test_aprd_bytes_match_the_standard_layout() -> None:
    # APRD to position 0, register 0x0000, 2 bytes: as SOEM puts it on the wire
    raw = encode_frame([Datagram(Command.APRD, 0, 0x0000, b"\x00\x00", index=0x2A)], pad=False)
    assert raw[12:14] == b"\x88\xa4"
    header = struct.unpack_from("<H", raw, 14)[0]
    assert header & 0x07FF == 10 + 2 + 2  # datagram header + data + WKC
    assert header >> 12 == 1  # EtherCAT DLPDUs
    assert raw[16:26] == bytes([1, 0x2A, 0, 0, 0, 0, 2, 0, 0, 0])
    assert raw[26:] == b"\x00\x00" + b"\x00\x00"


def test_more_bit_chains_datagrams_and_last_one_ends() -> None:
    raw = encode_frame([Datagram(Command.BRD, data=b"\0"), Datagram(Command.BRD, data=b"\0")])
    first_flags = struct.unpack_from("<H", raw, 16 + 6)[0]
    second_flags = struct.unpack_from("<H", raw, 16 + 13 + 6)[0]
    assert first_flags & 0x8000 and not second_flags & 0x8000
    assert len(raw) == MIN_ETH_FRAME  # short frames are padded


def test_logical_address_spans_adp_and_ado() -> None:
    d = Datagram.logical(Command.LRW, 0x12345678, b"\0")
    assert (d.adp, d.ado, d.logical_address) == (0x5678, 0x1234, 0x12345678)


@given(frames)
def test_build_parse_round_trip(dgs: list[Datagram]) -> None:
    raw = encode_frame(dgs, src=b"\x01\x02\x03\x04\x05\x06")
    parsed = decode_frame(raw)
    assert parsed.src == b"\x01\x02\x03\x04\x05\x06"
    assert parsed.datagrams == dgs


@given(frames)
def test_walker_agrees_with_the_codec(dgs: list[Datagram]) -> None:
    raw = encode_frame(dgs)
    offsets = walk(raw)
    assert offsets is not None
    assert len(offsets) == len(dgs)
    for off, d in zip(offsets, dgs, strict=True):
        assert raw[off] == d.command
        assert struct.unpack_from("<H", raw, off + 6)[0] & 0x07FF == len(d.data)


@settings(max_examples=examples(300, 40), deadline=None)  # a loaded CI box must not make it flaky
@given(frames, st.data())
def test_truncated_frames_are_rejected_by_both(dgs: list[Datagram], data: st.DataObject) -> None:
    raw = encode_frame(dgs, pad=False)
    cut = data.draw(st.integers(0, len(raw) - 1))
    short = raw[:cut]
    assert walk(short) is None
    with pytest.raises(FrameError):
        decode_frame(short)


@settings(max_examples=examples(500, 50), deadline=None)
@given(frames, st.data())
def test_corrupted_frames_never_crash_and_both_agree(
    dgs: list[Datagram], data: st.DataObject
) -> None:
    raw = bytearray(encode_frame(dgs))
    for _ in range(data.draw(st.integers(1, 4))):
        pos = data.draw(st.integers(ETH_HEADER_LEN, len(raw) - 1))
        raw[pos] = data.draw(st.integers(0, 255))
    offsets = walk(raw)
    try:
        decode_frame(raw)
    except FrameError:
        assert offsets is None
    else:
        assert offsets is not None


@given(st.binary(max_size=120))
def test_random_bytes_are_rejected_or_parsed_never_raise_otherwise(raw: bytes) -> None:
    try:
        decode_frame(raw)
    except FrameError:
        pass
    walk(raw)  # must not raise


def test_wrong_ethertype_and_frame_type_are_refused() -> None:
    raw = bytearray(encode_frame([Datagram(Command.NOP, data=b"\0")]))
    raw[12:14] = b"\x08\x00"
    with pytest.raises(FrameError, match="EtherType"):
        decode_frame(raw)
    assert walk(raw) is None
    raw = bytearray(encode_frame([Datagram(Command.NOP, data=b"\0")]))
    raw[15] = (raw[15] & 0x0F) | 0x40  # type 4: network variables
    with pytest.raises(FrameError, match="frame type"):
        decode_frame(raw)
    assert walk(raw) is None


def test_header_length_must_match_the_datagrams() -> None:
    raw = bytearray(encode_frame([Datagram(Command.NOP, data=b"\0\0")], pad=False))
    struct.pack_into("<H", raw, 14, (1 << 12) | 13)  # one byte short
    assert walk(raw) is None
    with pytest.raises(FrameError):
        decode_frame(raw)


def test_encoder_refuses_what_no_frame_holds() -> None:
    with pytest.raises(FrameError):
        encode_frame([])
    with pytest.raises(FrameError):
        encode_frame([Datagram(Command.LRW, data=bytes(MAX_ECAT_LEN))])
    with pytest.raises(FrameError):
        encode_frame([Datagram(300)])


def test_walk_uses_only_the_valid_length_of_a_receive_buffer() -> None:
    raw = encode_frame([Datagram(Command.BRD, data=b"\0\0")])
    buf = bytearray(2048)
    buf[: len(raw)] = raw
    assert walk(buf, len(raw)) == [16]
    assert walk(buf, 20) is None
