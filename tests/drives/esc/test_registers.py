"""One ESC: registers a master uses, AL state machine, SII access, SMs, FMMUs, DC, watchdog."""

from __future__ import annotations

import struct

import pytest

from gtecat.drives.esc.registers import Esc, FrameTime, MailboxType, Reg, mailbox_error
from gtecat.drives.esc.sii import build_sii, sii_info_for
from gtecat.drives.slave import AlState, AlStatusCode
from gtecat.eni.model import Identity
from tests.drives.esc.mini import MiniSlave, sdo_download_request, sdo_upload_request


class Clock:
    def __init__(self) -> None:
        self.t = 1_000_000_000

    def __call__(self) -> int:
        return self.t


def make(mailbox: bool = True, rx_bits: int = 48, tx_bits: int = 80, **kw) -> tuple[Esc, Clock]:
    clock = Clock()
    slave = MiniSlave(0, "S", Identity(0x1234, 0x5678, 2), rx_bits, tx_bits, mailbox)
    esc = Esc(
        slave, build_sii(sii_info_for(slave)), clock=clock, frame_time=FrameTime(clock.t), **kw
    )
    return esc, clock


def sm_bytes(start: int, length: int, control: int, enable: int = 1) -> bytes:
    return struct.pack("<HHBBBB", start, length, control, 0, enable, 0)


def configure(esc: Esc, out_len: int | None = None, in_len: int | None = None) -> None:
    """Program the SMs the way SOEM does from the SII (lengths from the mapping)."""
    rx, tx = esc.slave.pdo_sizes()
    out_len = (rx + 7) // 8 if out_len is None else out_len
    in_len = (tx + 7) // 8 if in_len is None else in_len
    if esc.slave.has_mailbox:
        assert esc.write(Reg.SM0, sm_bytes(0x1000, 128, 0x26) + sm_bytes(0x1080, 128, 0x22))
        assert esc.write(Reg.SM0 + 16, sm_bytes(0x1100, out_len, 0x64, int(out_len > 0)))
        assert esc.write(Reg.SM0 + 24, sm_bytes(0x1400, in_len, 0x20, int(in_len > 0)))
    else:
        assert esc.write(Reg.SM0, sm_bytes(0x1000, out_len, 0x64, int(out_len > 0)))
        assert esc.write(Reg.SM0 + 8, sm_bytes(0x1400, in_len, 0x20, int(in_len > 0)))


def request(esc: Esc, state: int) -> tuple[int, int]:
    esc.write(Reg.AL_CONTROL, struct.pack("<H", state))
    status = esc.read(Reg.AL_STATUS, 2)
    code = esc.read(Reg.AL_STATUS_CODE, 2)
    assert status is not None and code is not None
    return status[0], struct.unpack("<H", code)[0]


def to_op(esc: Esc) -> None:
    configure(esc)
    for st in (AlState.PREOP, AlState.SAFEOP, AlState.OP):
        assert request(esc, st) == (st, 0)


# --- identification -----------------------------------------------------------------------------
def test_identification_registers() -> None:
    esc, _ = make()
    assert esc.read(Reg.TYPE, 1) == b"\x11"
    assert esc.read(Reg.FMMU_COUNT, 2) == b"\x08\x08"
    features = struct.unpack("<H", esc.read(Reg.FEATURES, 2) or b"")[0]
    assert features & 0x0004 and features & 0x0008  # DC, 64 bit
    assert esc.read(Reg.PORT_DESCRIPTOR, 1) == b"\x0f"


def test_read_only_registers_take_the_write_but_keep_their_value() -> None:
    esc, _ = make()
    assert esc.write(Reg.TYPE, b"\x99")  # accepted (the WKC counts it), not stored
    assert esc.read(Reg.TYPE, 1) == b"\x11"
    assert esc.write(Reg.AL_STATUS, b"\x08\x00")
    assert esc.read(Reg.AL_STATUS, 1) == b"\x01"
    assert esc.write(Reg.STATION_ADDRESS, b"\x01\x10")
    assert esc.station_address == 0x1001


def test_dl_status_shows_the_place_in_the_chain() -> None:
    esc, _ = make()
    esc.set_topology(0, 3)
    middle = struct.unpack("<H", esc.read(Reg.DL_STATUS, 2) or b"")[0]
    assert middle & 0x0300 == 0x0200 and middle & 0x0C00 == 0x0800  # ports 0 and 1 open
    esc.set_topology(2, 3)
    last = struct.unpack("<H", esc.read(Reg.DL_STATUS, 2) or b"")[0]
    assert last & 0x0300 == 0x0200 and last & 0x0C00 == 0x0400  # port 1 closed


# --- AL state machine -----------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("setup", "target", "expected"),
    [
        ("init", AlState.PREOP, (0x02, 0)),
        ("init", AlState.SAFEOP, (0x11, AlStatusCode.INVALID_REQUESTED_STATE_CHANGE)),
        ("init", AlState.OP, (0x11, AlStatusCode.INVALID_REQUESTED_STATE_CHANGE)),
        ("init", AlState.BOOT, (0x11, AlStatusCode.BOOTSTRAP_NOT_SUPPORTED)),
        ("init", 5, (0x11, AlStatusCode.UNKNOWN_REQUESTED_STATE)),
        ("preop", AlState.SAFEOP, (0x04, 0)),
        ("preop", AlState.OP, (0x12, AlStatusCode.INVALID_REQUESTED_STATE_CHANGE)),
        ("preop", AlState.INIT, (0x01, 0)),
        ("safeop", AlState.OP, (0x08, 0)),
        ("safeop", AlState.PREOP, (0x02, 0)),
        ("op", AlState.SAFEOP, (0x04, 0)),
        ("op", AlState.INIT, (0x01, 0)),
    ],
)
def test_transitions(setup: str, target: int, expected: tuple[int, int]) -> None:
    esc, _ = make()
    configure(esc)
    for st in {"init": [], "preop": [2], "safeop": [2, 4], "op": [2, 4, 8]}[setup]:
        assert request(esc, st)[1] == 0
    assert request(esc, target) == expected


def test_preop_needs_valid_mailbox_sms() -> None:
    esc, _ = make()
    assert request(esc, AlState.PREOP) == (0x11, AlStatusCode.INVALID_MAILBOX_CONFIGURATION)
    esc, _ = make(mailbox=False)
    assert request(esc, AlState.PREOP) == (0x02, 0)  # no mailbox, nothing to check


@pytest.mark.parametrize(
    ("out_len", "in_len", "code"),
    [
        (5, 10, AlStatusCode.INVALID_OUTPUT_CONFIGURATION),
        (6, 12, AlStatusCode.INVALID_INPUT_CONFIGURATION),
        (0, 10, AlStatusCode.INVALID_OUTPUT_CONFIGURATION),
        (6, 10, AlStatusCode.NO_ERROR),
    ],
)
def test_safeop_checks_the_process_data_sms(out_len: int, in_len: int, code: int) -> None:
    esc, _ = make()
    configure(esc, out_len, in_len)
    request(esc, AlState.PREOP)
    status, got = request(esc, AlState.SAFEOP)
    assert got == code
    assert status == (0x04 if code == 0 else 0x12)


def test_a_stale_extra_sm_left_enabled_does_not_fail_the_safeop_check() -> None:
    # SOEM's config_init clears SM0-3 only; an SM4/SM5 another master (or stray frames)
    # left enabled is not one of the buffers the slave serves, so it must not count.
    esc, _ = make()
    assert esc.write(Reg.SM0 + 32, sm_bytes(0x1800, 0x2E, 0x20, 1))  # SM4: a stale input SM
    assert esc.write(Reg.SM0 + 40, sm_bytes(0x1900, 0x13, 0x64, 1))  # SM5: a stale output SM
    configure(esc)
    request(esc, AlState.PREOP)
    assert request(esc, AlState.SAFEOP) == (0x04, 0)


def test_an_error_must_be_acknowledged_before_going_up() -> None:
    esc, _ = make()
    configure(esc, 5, 10)
    request(esc, AlState.PREOP)
    assert request(esc, AlState.SAFEOP) == (0x12, AlStatusCode.INVALID_OUTPUT_CONFIGURATION)
    configure(esc)  # fixed, but not acknowledged
    assert request(esc, AlState.SAFEOP) == (0x12, AlStatusCode.INVALID_OUTPUT_CONFIGURATION)
    assert request(esc, AlState.SAFEOP | 0x10) == (0x04, 0)


def test_ack_of_the_current_state_clears_the_error() -> None:
    esc, _ = make()
    configure(esc)
    assert request(esc, AlState.OP) == (0x11, AlStatusCode.INVALID_REQUESTED_STATE_CHANGE)
    assert request(esc, AlState.INIT | 0x10) == (0x01, 0)


def test_a_lower_state_is_taken_without_ack() -> None:
    esc, _ = make()
    configure(esc, 5, 10)
    request(esc, AlState.PREOP)
    request(esc, AlState.SAFEOP)  # refused: PREOP + error
    assert request(esc, AlState.INIT) == (0x01, 0)


def test_al_status_change_raises_the_event_until_read() -> None:
    esc, _ = make()
    configure(esc)
    esc.write(Reg.EVENT_MASK, b"\x08\x00")
    esc.write(Reg.AL_CONTROL, b"\x02\x00")
    assert esc.event_irq & 0x0008
    esc.read(Reg.AL_STATUS, 2)
    assert not esc.event_irq & 0x0008


# --- SII EEPROM ---------------------------------------------------------------------------------
def eeprom(esc: Esc, command: int, word: int, enable: int = 0) -> int:
    esc.write(Reg.EEPROM_CONTROL, struct.pack("<HIH", command | enable, word, 0)[:6])
    return struct.unpack("<H", esc.read(Reg.EEPROM_CONTROL, 2) or b"")[0]


def test_eeprom_read_gives_eight_bytes_and_is_busy_for_a_while() -> None:
    esc, clock = make(eeprom_busy_ns=50_000)
    status = eeprom(esc, 0x0100, 0x0008)
    assert status & 0x8000  # busy
    assert status & 0x0040  # 8-byte reads
    clock.t += 60_000
    status = struct.unpack("<H", esc.read(Reg.EEPROM_CONTROL, 2) or b"")[0]
    assert not status & 0x8000 and not status & 0x0700
    assert esc.read(Reg.EEPROM_DATA, 8) == bytes(esc.sii[16:24])
    assert struct.unpack("<I", (esc.read(Reg.EEPROM_DATA, 4) or b"")[:4])[0] == 0x1234


def test_eeprom_command_while_busy_is_ignored() -> None:
    esc, clock = make(eeprom_busy_ns=50_000)
    eeprom(esc, 0x0100, 0x0008)
    eeprom(esc, 0x0100, 0x000A)  # ignored
    clock.t += 60_000
    esc.read(Reg.EEPROM_CONTROL, 2)
    assert esc.read(Reg.EEPROM_DATA, 4) == bytes(esc.sii[16:20])


def test_eeprom_write_needs_write_enable_and_nop_clears_errors() -> None:
    esc, _ = make(eeprom_busy_ns=0)
    esc.write(Reg.EEPROM_DATA, b"\xaa\x55")
    status = eeprom(esc, 0x0200, 0x0004)
    assert status & 0x4000  # write enable error
    assert eeprom(esc, 0x0000, 0) & 0x7800 == 0
    esc.write(Reg.EEPROM_DATA, b"\xaa\x55")
    status = eeprom(esc, 0x0200, 0x0004, enable=1)
    assert not status & 0x7800
    assert bytes(esc.sii[8:10]) == b"\xaa\x55"
    eeprom(esc, 0x0400, 0)  # reload: the alias comes from word 4
    assert esc.station_alias == 0x55AA


def test_eeprom_beyond_the_content_reads_ffff() -> None:
    esc, _ = make(eeprom_busy_ns=0)
    eeprom(esc, 0x0100, 0x7FF0)
    assert esc.read(Reg.EEPROM_DATA, 8) == b"\xff" * 8


# --- mailbox ------------------------------------------------------------------------------------
def preop(esc: Esc) -> None:
    configure(esc)
    assert request(esc, AlState.PREOP) == (0x02, 0)


def test_mailbox_roundtrip_and_buffer_rules() -> None:
    esc, _ = make()
    configure(esc)
    req = sdo_upload_request(0x2000, 0)
    assert not esc.write(0x1000, req + bytes(128 - len(req)))  # INIT: mailbox off
    request(esc, AlState.PREOP)
    assert esc.read(0x1080, 128) is None  # nothing to read yet
    assert esc.write(0x1000, req + bytes(128 - len(req)))
    assert (esc.read(0x0805, 1) or b"\0")[0] & 0x08  # SM0 full
    assert not esc.write(0x1000, bytes(128))  # full: refused
    esc.service()
    assert not (esc.read(0x0805, 1) or b"\0")[0] & 0x08
    assert (esc.read(0x080D, 1) or b"\0")[0] & 0x08  # answer waiting
    head = esc.read(0x1080, 16)  # not the last byte: stays full
    assert head is not None and head[8] == 0x4B and head[12:14] == b"\x34\x12"
    answer = esc.read(0x1080, 128)
    assert answer is not None and answer[:16] == head[:16]
    assert esc.read(0x1080, 128) is None  # read out: empty again


def test_mailbox_repeat_request_resends_the_last_answer() -> None:
    esc, _ = make()
    preop(esc)
    req = sdo_upload_request(0x1000, 0)
    esc.write(0x1000, req + bytes(128 - len(req)))
    esc.service()
    first = esc.read(0x1080, 128)
    assert first is not None
    # the master lost the frame: toggle the repeat bit (SOEM writes 080Dh..080Eh)
    activate = (esc.read(0x080E, 1) or b"\0")[0]
    assert esc.write(0x080D, bytes([0, activate ^ 0x02]))
    assert (esc.read(0x080F, 1) or b"\0")[0] & 0x02 == (activate ^ 0x02) & 0x02
    assert esc.read(0x1080, 128) == first


def test_link_counter_runs_1_to_7() -> None:
    esc, _ = make()
    preop(esc)
    counters = []
    for k in range(9):
        req = sdo_upload_request(0x2000, 0, counter=k % 7 + 1)  # a master counts 1..7
        esc.write(0x1000, req + bytes(128 - len(req)))
        esc.service()
        counters.append(((esc.read(0x1080, 128) or b"\0" * 6)[5] >> 4) & 7)
    assert counters == [1, 2, 3, 4, 5, 6, 7, 1, 2]


def test_unknown_protocol_gets_a_mailbox_error() -> None:
    esc, _ = make()
    preop(esc)
    msg = struct.pack("<HHBB", 4, 0, 0, MailboxType.EOE) + bytes(4)  # EoE: not offered
    esc.write(0x1000, msg + bytes(128 - len(msg)))
    esc.service()
    answer = esc.read(0x1080, 128) or b""
    assert answer[5] & 0x0F == MailboxType.ERR
    assert struct.unpack_from("<HH", answer, 6) == (1, 0x02)


def test_a_length_beyond_the_buffer_is_an_invalid_size() -> None:
    esc, _ = make()
    preop(esc)
    msg = struct.pack("<HHBB", 500, 0, 0, MailboxType.COE)
    esc.write(0x1000, msg + bytes(128 - len(msg)))
    esc.service()
    assert (esc.read(0x1080, 128) or b"")[6:10] == struct.pack("<HH", 1, 0x08)


def test_a_slave_exception_becomes_a_mailbox_error_not_a_crash() -> None:
    esc, _ = make()
    preop(esc)

    def broken(request: bytes) -> bytes:
        raise RuntimeError("bug")

    esc.slave.mailbox = broken  # type: ignore[method-assign]
    req = sdo_download_request(0x2000, 0, b"\x01\x00")
    esc.write(0x1000, req + bytes(128 - len(req)))
    esc.service()
    answer = esc.read(0x1080, 128) or b""
    assert answer[5] & 0x0F == MailboxType.ERR
    assert answer[6:10] == mailbox_error(1)[6:10]  # mailbox error "syntax"
    assert esc.errors == 1


# --- process data and FMMUs ---------------------------------------------------------------------
def fmmu(lstart: int, length: int, lsb: int, leb: int, pstart: int, psb: int, ftype: int) -> bytes:
    return struct.pack("<IHBBHBBB3x", lstart, length, lsb, leb, pstart, psb, ftype, 1)


def test_outputs_reach_the_slave_when_the_last_byte_is_written() -> None:
    esc, _ = make()
    to_op(esc)
    assert esc.write(0x1100, b"\x01\x02\x03")
    assert bytes(esc.slave.rx) == bytes(6)  # not complete yet
    assert esc.write(0x1103, b"\x04\x05\x06")
    assert bytes(esc.slave.rx) == b"\x01\x02\x03\x04\x05\x06"
    assert esc.slave.outputs_valid


def test_sm_access_follows_the_state() -> None:
    esc, _ = make()
    configure(esc)
    request(esc, AlState.PREOP)
    request(esc, AlState.SAFEOP)
    esc.slave.tx[:] = bytes(range(10))
    esc.load_inputs()
    assert esc.read(0x1400, 10) == bytes(range(10))  # inputs from SAFEOP
    assert not esc.write(0x1100, bytes(6))  # outputs only in OP
    request(esc, AlState.OP)
    assert esc.write(0x1100, bytes(6))


def test_lrw_through_byte_fmmus_counts_three() -> None:
    esc, _ = make()
    to_op(esc)
    esc.write(Reg.FMMU0, fmmu(0x100, 6, 0, 7, 0x1100, 0, 2) + fmmu(0x106, 10, 0, 7, 0x1400, 0, 1))
    esc.slave.tx[:] = bytes(range(10, 20))
    esc.load_inputs()
    data = bytearray(b"\xaa" * 16)
    assert esc.logical(12, 0x100, data) == 3
    assert bytes(esc.slave.rx) == b"\xaa" * 6
    assert bytes(data[6:]) == bytes(range(10, 20))
    assert esc.logical(10, 0x100, bytearray(16)) == 1  # LRD: read only
    assert esc.logical(11, 0x100, bytearray(16)) == 1  # LWR: write only
    assert esc.logical(12, 0x200, bytearray(16)) == 0  # not mapped here


def test_bit_fmmus_move_only_their_bits() -> None:
    esc, _ = make(mailbox=False, rx_bits=2, tx_bits=3)
    configure(esc)
    for st in (2, 4, 8):
        request(esc, st)
    # outputs: logical 0x10 bits 3..4 -> SM0 bits 0..1; inputs: logical 0x10 bits 5..7 -> SM1
    esc.write(Reg.FMMU0, fmmu(0x10, 1, 3, 4, 0x1000, 0, 2) + fmmu(0x10, 1, 5, 7, 0x1400, 0, 1))
    esc.slave.tx[0] = 0b101
    esc.load_inputs()
    data = bytearray([0b0001_1000])
    assert esc.logical(12, 0x10, data) == 3
    assert esc.slave.rx[0] & 0b11 == 0b11
    assert data[0] == 0b1011_1000  # bits 5..7 = 101, bits 3..4 untouched


def test_overlapping_fmmus_take_outputs_before_putting_inputs() -> None:
    esc, _ = make()
    to_op(esc)
    esc.write(Reg.FMMU0, fmmu(0, 6, 0, 7, 0x1100, 0, 2) + fmmu(0, 10, 0, 7, 0x1400, 0, 1))
    esc.slave.tx[:] = b"\x55" * 10
    esc.load_inputs()
    data = bytearray(b"\x11" * 10)
    esc.logical(12, 0, data)
    assert bytes(esc.slave.rx) == b"\x11" * 6 and bytes(data) == b"\x55" * 10


# --- DC -------------------------------------------------------------------------------------------
def test_receive_times_offset_and_drift_lock() -> None:
    esc, clock = make()
    esc.set_topology(1, 3)
    esc.ft.t_ns = clock.t
    esc.write(Reg.DC_RECEIVE_TIME0, bytes(4))
    p0, p1 = struct.unpack("<II", esc.read(Reg.DC_RECEIVE_TIME0, 8) or b"")
    local = struct.unpack("<Q", esc.read(Reg.DC_RECEIVE_TIME_PU, 8) or b"")[0]
    assert p0 == local & 0xFFFFFFFF
    assert p1 - p0 == 2 * 800  # back through port 1: one more slave behind
    # SOEM: offset = master time - local receive time
    esc.write(Reg.DC_SYSTEM_OFFSET, struct.pack("<q", 5_000_000_000 - local))
    assert struct.unpack("<Q", esc.read(Reg.DC_SYSTEM_TIME, 8) or b"")[0] == 5_000_000_000
    esc.ft.t_ns += 1000
    assert struct.unpack("<Q", esc.read(Reg.DC_SYSTEM_TIME, 8) or b"")[0] == 5_000_001_000
    # drift compensation: the reference says 7e9; with 300 ns delay we lock onto 7e9 + 300
    esc.write(Reg.DC_SYSTEM_DELAY, struct.pack("<I", 300))
    esc.write(Reg.DC_SYSTEM_TIME, struct.pack("<Q", 7_000_000_000))
    assert struct.unpack("<Q", esc.read(Reg.DC_SYSTEM_TIME, 8) or b"")[0] == 7_000_000_300


# --- watchdog -------------------------------------------------------------------------------------
@pytest.mark.parametrize("trips", [False, True])
def test_sm_watchdog(trips: bool) -> None:
    esc, clock = make(watchdog_trips=trips)
    to_op(esc)
    assert esc.watchdog_ns() == 100_000_000  # defaults: 100 us x 1000
    esc.write(0x1100, bytes(6))
    clock.t += 50_000_000
    assert not esc.check_watchdog(clock.t)
    clock.t += 60_000_000
    assert esc.check_watchdog(clock.t)
    assert (esc.read(Reg.WD_STATUS_PD, 1) or b"\1")[0] & 1 == 0
    status, code = struct.unpack("<HxxH", esc.read(Reg.AL_STATUS, 6) or b"")
    if trips:
        assert (status, code) == (0x14, AlStatusCode.SYNC_MANAGER_WATCHDOG)
    else:
        assert (status, code) == (0x08, 0)
        esc.ft.t_ns = clock.t
        esc.write(0x1100, bytes(6))
        assert (esc.read(Reg.WD_STATUS_PD, 1) or b"\0")[0] & 1 == 1
