"""SDO abort codes: the table, the exception, and one real refusal per code the drive produces."""

from __future__ import annotations

import struct
from collections.abc import Callable

import pytest

from gtecat.drives.abort import ABORT_TEXT, SdoAbort, SdoAbortCode, abort_text
from gtecat.drives.coe import (
    CoeService,
    SdoClient,
    SdoExpedited,
    build_abort,
    build_coe,
    initiate_cmd,
)
from gtecat.drives.slave import AlState
from gtecat.eni.errors import GtecatError
from tests.drives.test_drive import Rig

# cia402-facts.md section 5, every code
FACTS_CODES = [
    0x05030000,
    0x05040000,
    0x05040001,
    0x05040002,
    0x05040003,
    0x05040004,
    0x05040005,
    0x06010000,
    0x06010001,
    0x06010002,
    0x06010003,
    0x06010004,
    0x06010005,
    0x06010006,
    0x06020000,
    0x06040041,
    0x06040042,
    0x06040043,
    0x06040047,
    0x06060000,
    0x06070010,
    0x06070012,
    0x06070013,
    0x06090011,
    0x06090030,
    0x06090031,
    0x06090032,
    0x06090036,
    0x08000000,
    0x08000020,
    0x08000021,
    0x08000022,
    0x08000023,
    0x08000024,
]


def test_every_facts_code_is_in_the_enum_with_text() -> None:
    assert sorted(int(c) for c in SdoAbortCode) == sorted(FACTS_CODES)
    assert set(ABORT_TEXT) == set(SdoAbortCode)


@pytest.mark.parametrize("code", FACTS_CODES)
def test_every_code_round_trips_through_an_abort_frame(code: int) -> None:
    frame = build_coe(CoeService.SDO_RESPONSE, build_abort(0x6040, 0, code), counter=1)
    client = SdoClient(lambda _msg: frame)
    with pytest.raises(SdoAbort) as e:
        client.upload(0x6040, 0)
    assert e.value.code == code and isinstance(e.value.code, SdoAbortCode)
    assert (e.value.index, e.value.subindex) == (0x6040, 0)
    assert abort_text(code) in str(e.value)


def test_message_format_and_vendor_codes() -> None:
    err = SdoAbort(0x06010002, 0x6041, 0)
    assert str(err) == "0x6041:00: attempt to write a read-only object (0x06010002)"
    assert isinstance(err, GtecatError)
    vendor = SdoAbort(0x0BADC0DE, 0x2000, 3, "vendor says no")
    assert vendor.code == 0x0BADC0DE
    assert str(vendor) == "0x2000:03: unknown abort code (0x0BADC0DE): vendor says no"


def _raw(rig: Rig, command: int, index: int, sub: int, data: bytes = bytes(4)) -> bytes:
    req = bytes([command]) + struct.pack("<HB", index, sub) + data
    return rig.drive.mailbox(build_coe(CoeService.SDO_REQUEST, req, counter=1))


def _code_of(answer: bytes) -> int:
    body = answer[8:]
    assert body[0] == 0x80, body.hex()
    return struct.unpack_from("<I", body, 4)[0]


def _write(index: int, sub: int, data: bytes, **kw: object) -> Callable[[Rig], None]:
    return lambda rig: rig.sdo.download(index, sub, data, **kw)  # type: ignore[arg-type]


def _read(index: int, sub: int, **kw: object) -> Callable[[Rig], None]:
    return lambda rig: rig.sdo.upload(index, sub, **kw)  # type: ignore[arg-type]


def _preop(action: Callable[[Rig], None]) -> Callable[[Rig], None]:
    def run(rig: Rig) -> None:
        rig.drive.request_state(AlState.PREOP)
        action(rig)

    return run


def _too_long(r: Rig) -> None:
    """Three PDOs of 16 x 64 bits (placeholders) exceed the 256-byte process data limit."""
    r.write(0x1C12, 0, fmt="B")
    for pdo in (0x1601, 0x1602, 0x1603):
        r.write(pdo, 0, fmt="B")
        for k in range(1, 17):
            r.write(pdo, 0x2F000040 | (k << 8), k, fmt="I")
        r.write(pdo, 16, fmt="B")
        r.write(0x1C12, pdo, pdo - 0x1600, fmt="H")
    r.write(0x1C12, 3, fmt="B")


# (code, action) pairs: one refusal per code the drive itself can produce
REFUSALS: list[tuple[int, Callable[[Rig], None]]] = [
    (0x06020000, _read(0x5FFF, 0)),  # object does not exist
    (0x06090011, _read(0x6041, 1)),  # subindex does not exist
    (0x06090011, _read(0x1018, 9)),
    (0x06010002, _write(0x6041, 0, b"\x00\x00")),  # read-only
    (0x06010002, _write(0x1018, 1, b"\x00\x00\x00\x00")),
    (0x06070012, _write(0x6040, 0, b"\x00\x00\x00")),  # length too high
    (0x06070013, _write(0x6081, 0, b"\x00\x00")),  # length too low
    (0x06090030, _write(0x6060, 0, b"\x07")),  # value range (unsupported mode)
    (0x06090031, _write(0x605A, 0, b"\x09\x00")),  # too high
    (0x06090032, _write(0x605D, 0, b"\x00\x00")),  # too low
    (0x08000022, _write(0x1C12, 0, b"\x00")),  # not in this AL state (OP)
    (0x08000022, _write(0x1600, 0, b"\x00")),
    (0x06010003, _preop(_write(0x1600, 1, b"\x10\x00\x40\x60"))),  # SI0 must be 0
    (0x06010003, _preop(_write(0x1C12, 3, b"\x00\x16"))),
    (
        0x06040041,
        _preop(lambda r: (r.write(0x1601, 0, fmt="B"), r.write(0x1601, 0x605A0010, 1, fmt="I"))),
    ),  # not mappable
    (
        0x06040041,
        _preop(lambda r: (r.write(0x1601, 0, fmt="B"), r.write(0x1601, 0x60410010, 1, fmt="I"))),
    ),  # TxPDO-only
    (0x06040042, _preop(_too_long)),  # PDO length exceeded
    (
        0x06040043,
        _preop(lambda r: (r.write(0x1601, 0, fmt="B"), r.write(0x1601, 0x60400000, 1, fmt="I"))),
    ),  # 0 bits
    (0x06070010, _preop(_write(0x1C12, 0, b"\x01\x00\x00", complete_access=True))),
    (0x05040001, lambda r: _raise_code(_raw(r, 0xE0, 0x6041, 0))),  # bad command specifier
    (0x05030000, lambda r: _raise_code(_toggle_error(r))),
    (0x08000000, lambda r: _raise_code(_hook_bug(r))),
]


def _raise_code(answer: bytes) -> None:
    raise SdoAbort(_code_of(answer), 0, 0)


def _toggle_error(rig: Rig) -> bytes:
    big = bytes(300)
    rig.drive.od.add_var(0x2FF0, "blob", 0x000A, max_size=400)  # OCTET_STRING
    rig.drive.od.find(0x2FF0, 0).value = big
    assert rig.sdo.upload(0x2FF0, 0) == big
    up = SdoExpedited.build(
        {"cmd": initiate_cmd(2), "index": 0x2FF0, "subindex": 0, "data": bytes(4)}
    )
    rig.drive.mailbox(build_coe(CoeService.SDO_REQUEST, up, counter=1))
    # first segment must carry toggle 0: send toggle 1
    return rig.drive.mailbox(build_coe(CoeService.SDO_REQUEST, b"\x70" + bytes(7), counter=2))


def _hook_bug(rig: Rig) -> bytes:
    def broken() -> int:
        raise RuntimeError("bug in a getter")

    rig.drive.od.add_var(0x2FF1, "broken", 0x0007, getter=broken)
    return _raw(rig, 0x40, 0x2FF1, 0)


@pytest.mark.parametrize(("code", "action"), REFUSALS, ids=[f"{c:08X}" for c, _ in REFUSALS])
def test_refusal_gives_the_standard_code(code: int, action: Callable[[Rig], None]) -> None:
    rig = Rig()
    with pytest.raises(SdoAbort) as e:
        action(rig)
    assert e.value.code == code
