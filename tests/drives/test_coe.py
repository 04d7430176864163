"""Mailbox/CoE/SDO codec and SdoClient -> mailbox -> SdoServer round trips."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.drives.abort import SdoAbort, SdoAbortCode
from gtecat.drives.coe import (
    CoeHeader,
    CoeService,
    MailboxHeader,
    MailboxType,
    SdoClient,
    SdoInitiateCommand,
    SdoSegmentCommand,
    advance_counter,
    build_coe,
    build_mailbox,
    next_counter,
    parse_mailbox,
)
from gtecat.drives.od import DataType, ObjectDictionary
from gtecat.drives.sdo_server import SdoServer
from gtecat.drives.slave import AlState


def blob_od(size: int = 0) -> ObjectDictionary:
    od = ObjectDictionary()
    od.add_var(0x2000, "blob", DataType.OCTET_STRING, max_size=4096, default=bytes(size))
    od.add_var(0x2001, "u32", DataType.UINT32)
    od.add_var(0x2002, "u8", DataType.UINT8)
    return od


class Wire:
    """Records every message both ways."""

    def __init__(self, server: SdoServer, al_state: AlState = AlState.PREOP) -> None:
        self.server = server
        self.al_state = al_state
        self.sent: list[bytes] = []
        self.received: list[bytes] = []

    def __call__(self, msg: bytes) -> bytes | None:
        self.sent.append(msg)
        answer = self.server.handle(msg, self.al_state)
        if answer is not None:
            self.received.append(answer)
        return answer


# --- byte-exact frames (SOEM ethercatcoe.c builds the same bytes) --------------------------
def test_expedited_download_request_bytes() -> None:
    wire = Wire(SdoServer(blob_od()))
    SdoClient(wire).download(0x2002, 0, b"\x08")
    # length 10, address 0, channel/priority 0, type CoE | counter 1 << 4
    assert wire.sent[0] == bytes.fromhex(
        "0a00 0000 00 13 0020 2f 0220 00 08000000".replace(" ", "")
    )
    # answer: SDO response, scs 3 (download initiate response)
    assert wire.received[0][6:] == bytes.fromhex("0030 60 0220 00 00000000".replace(" ", ""))


def test_expedited_upload_response_bytes() -> None:
    od = blob_od()
    od.find(0x2001, 0).value = 0x11223344
    wire = Wire(SdoServer(od))
    assert SdoClient(wire).upload(0x2001, 0) == bytes.fromhex("44332211")
    assert wire.sent[0][6:] == bytes.fromhex("0020 40 0120 00 00000000".replace(" ", ""))
    assert wire.received[0][6:] == bytes.fromhex("0030 43 0120 00 44332211".replace(" ", ""))


def test_abort_frame_bytes() -> None:
    wire = Wire(SdoServer(blob_od()))
    with pytest.raises(SdoAbort):
        SdoClient(wire).upload(0x5555, 7)
    # CoE service 2 "SDO request" carries an abort (ETG.1000.6 Table 40; SOEM, IgH)
    assert wire.received[0][6:] == bytes.fromhex("0020 80 5555 07 00000206".replace(" ", ""))


@given(
    st.integers(0, 0xFFFF),
    st.integers(0, 0xFFFF),
    st.integers(0, 3),
    st.integers(0, 63),
    st.integers(0, 7),
    st.sampled_from(list(MailboxType)),
)
def test_mailbox_header_round_trip(length, address, prio, channel, counter, mtype) -> None:  # type: ignore[no-untyped-def]
    raw = MailboxHeader.build(
        {
            "length": length,
            "address": address,
            "bits": {
                "priority": prio,
                "channel": channel,
                "reserved": 0,
                "counter": counter,
                "type": int(mtype),
            },
        }
    )
    assert raw == struct.pack("<HHBB", length, address, channel | prio << 6, mtype | counter << 4)
    back = MailboxHeader.parse(raw)
    assert (back.length, back.address, back.bits.counter, back.bits.type) == (
        length,
        address,
        counter,
        mtype,
    )


@given(st.integers(0, 15), st.integers(0, 511))
def test_coe_header_round_trip(service: int, number: int) -> None:
    raw = CoeHeader.build({"service": service, "reserved": 0, "number": number})
    assert raw == struct.pack("<H", number | service << 12)
    assert CoeHeader.parse(raw).service == service


@given(st.integers(0, 255))
def test_command_bytes_parse_and_build_losslessly(byte: int) -> None:
    ini = SdoInitiateCommand.parse(bytes([byte]))
    assert ini.command == byte >> 5 and ini.complete_access == bool(byte & 0x10)
    assert ini.size == (byte >> 2) & 3 and ini.expedited == bool(byte & 2)
    assert SdoInitiateCommand.build(ini) == bytes([byte])
    seg = SdoSegmentCommand.parse(bytes([byte]))
    assert seg.toggle == bool(byte & 0x10) and seg.last == bool(byte & 1)
    assert SdoSegmentCommand.build(seg) == bytes([byte])


@pytest.mark.parametrize("start", range(9))
def test_advancing_a_counter_is_stepping_it(start: int) -> None:
    c = start
    for steps in range(30):
        assert advance_counter(start, steps) == c, (start, steps)
        c = next_counter(c)


def test_counter_runs_1_to_7() -> None:
    seq = [1]
    for _ in range(8):
        seq.append(next_counter(seq[-1]))
    assert seq == [1, 2, 3, 4, 5, 6, 7, 1, 2]
    wire = Wire(SdoServer(blob_od()))
    client = SdoClient(wire)
    for _ in range(9):
        client.upload(0x2001, 0)
    assert [parse_mailbox(m).counter for m in wire.sent] == [1, 2, 3, 4, 5, 6, 7, 1, 2]
    assert all(1 <= parse_mailbox(m).counter <= 7 for m in wire.received)


# --- round trips by size: expedited (<= 4), normal (<= 112), segmented -------------------
@pytest.mark.parametrize("size", [0, 1, 4, 5, 111, 112, 113, 119, 231, 232, 233, 1000])
def test_upload_and_download_round_trip(size: int) -> None:
    od = blob_od()
    wire = Wire(SdoServer(od))
    client = SdoClient(wire)
    payload = bytes((k * 7 + 3) & 0xFF for k in range(size))
    client.download(0x2000, 0, payload)
    assert od.find(0x2000, 0).value == payload
    n_down = len(wire.sent)
    assert client.upload(0x2000, 0) == payload
    n_up = len(wire.sent) - n_down
    if size <= 4:
        assert n_down == 1 and (size == 0 or wire.received[n_down][8] & 0x02)  # expedited
    if 4 < size <= 112:
        assert n_down == 1 and n_up == 1
    if size > 112:
        segments = -(-(size - 112) // 119)
        assert n_down == 1 + segments and n_up == 1 + segments
    assert all(len(m) <= 128 for m in wire.sent + wire.received)


@settings(max_examples=40, deadline=None)
@given(st.binary(max_size=700), st.sampled_from([32, 64, 128, 256, 1024]))
def test_round_trip_any_payload_any_mailbox_size(payload: bytes, mbx: int) -> None:
    od = blob_od()
    wire = Wire(SdoServer(od, mailbox_size=mbx))
    client = SdoClient(wire, mailbox_size=mbx)
    client.download(0x2000, 0, payload)
    assert client.upload(0x2000, 0) == payload
    assert all(len(m) <= mbx for m in wire.sent + wire.received)


def test_expedited_download_without_size_indicator_uses_object_size() -> None:
    od = blob_od()
    server = SdoServer(od)
    req = bytes([0x22]) + struct.pack("<HB", 0x2002, 0) + b"\x09\xaa\xbb\xcc"
    answer = server.handle(build_coe(CoeService.SDO_REQUEST, req, counter=1))
    assert answer[8] == 0x60
    assert od.find(0x2002, 0).value == 9


def test_abort_during_segmented_download_resets_the_transfer() -> None:
    od = blob_od()
    server = SdoServer(od)
    client = SdoClient(lambda m: server.handle(m))
    client.download(0x2000, 0, bytes(300))
    # a segment without an initiate is refused
    seg = build_coe(CoeService.SDO_REQUEST, b"\x00" + bytes(7), counter=3)
    answer = server.handle(seg)
    assert answer[8] == 0x80
    assert struct.unpack_from("<I", answer, 12)[0] == SdoAbortCode.COMMAND_SPECIFIER_INVALID


def test_client_abort_is_not_answered() -> None:
    server = SdoServer(blob_od())
    req = bytes([0x80]) + struct.pack("<HBI", 0x2000, 0, 0x05040000)
    assert server.handle(build_coe(CoeService.SDO_REQUEST, req, counter=1)) is None


@pytest.mark.parametrize(
    ("message", "detail"),
    [
        (b"\x01\x02", 0x06),  # shorter than a header
        (build_mailbox(b"\x00\x20", counter=1)[:7], 0x06),  # cut short
        (build_mailbox(b"abcd", counter=1, mbx_type=MailboxType.FOE), 0x02),
        # SDO Information is served (test_sdo_info.py); remote PDO requests are not
        (build_coe(CoeService.TXPDO_REMOTE_REQUEST, b"\x01\x00\x00\x00", counter=1), 0x04),
    ],
)
def test_mailbox_error_replies(message: bytes, detail: int) -> None:
    answer = SdoServer(blob_od()).handle(message)
    mbx = parse_mailbox(answer)
    assert mbx.mbx_type == MailboxType.ERR
    assert struct.unpack("<HH", mbx.data) == (1, detail)


def test_client_turns_a_mailbox_error_into_an_abort() -> None:
    error = build_mailbox(struct.pack("<HH", 1, 4), counter=1, mbx_type=MailboxType.ERR)
    with pytest.raises(SdoAbort) as e:
        SdoClient(lambda _m: error).upload(0x1000, 0)
    assert e.value.code == SdoAbortCode.GENERAL_ERROR and "SERVICE_NOT_SUPPORTED" in str(e.value)
    with pytest.raises(SdoAbort) as e:
        SdoClient(lambda _m: None).upload(0x1000, 0)
    assert e.value.code == SdoAbortCode.SDO_PROTOCOL_TIMED_OUT


def test_complete_access_of_1c12_and_1600_through_the_wire() -> None:
    from tests.drives.test_drive import Rig

    rig = Rig(op=False)
    rig.drive.request_state(AlState.PREOP)
    sdo = rig.sdo
    # the acontis fixture's init commands (acontis_training_slaves.xml): clear, then CA
    sdo.download(0x1C12, 0, b"\x00")
    sdo.download(0x1600, 0, b"\x02\x00" + struct.pack("<II", 0x60400010, 0x607A0020), True)
    sdo.download(0x1C12, 0, bytes.fromhex("010000160000"), complete_access=True)
    assert sdo.upload(0x1C12, 0, complete_access=True)[:4] == b"\x01\x00\x00\x16"
    ca = sdo.upload(0x1600, 0, complete_access=True)
    assert ca[:2] == b"\x02\x00"
    assert struct.unpack_from("<II", ca, 2) == (0x60400010, 0x607A0020)
    assert rig.drive.pdo_sizes()[0] == 48
