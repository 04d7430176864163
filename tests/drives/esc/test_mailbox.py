"""The firmware behind SM0/SM1: repeated messages, multi-message answers, emergencies.

The requests are hand-written bytes (ETG.1000.4 5.5 mailbox header, ETG.1000.6
5.6.3 SDO Information), not built with gtecat.drives.coe, so a codec bug cannot hide
on both sides.
"""

from __future__ import annotations

import struct

import pytest

from gtecat.drives.drive import Cia402Drive
from gtecat.drives.esc.registers import Esc, FrameTime, Reg
from gtecat.drives.esc.sii import build_sii, sii_info_for
from gtecat.drives.slave import AlState
from gtecat.eni.model import Direction, Identity, Pdo, PdoEntry
from tests.drives.esc.mini import MiniSlave, sdo_upload_request
from tests.drives.esc.test_registers import configure, make, request

SM0, SM1, SIZE = 0x1000, 0x1080, 128


def preop(esc: Esc) -> None:
    configure(esc)
    assert request(esc, AlState.PREOP) == (AlState.PREOP, 0)


def write_mailbox(esc: Esc, msg: bytes) -> bool:
    return esc.write(SM0, msg + bytes(SIZE - len(msg)))


def read_mailbox(esc: Esc) -> bytes | None:
    """What a master's FPRD of the whole SM1 buffer returns (None: empty, no WKC)."""
    return esc.read(SM1, SIZE)


def upload_value(answer: bytes) -> int:
    assert answer[5] & 0x0F == 3 and answer[8] & 0xE0 == 0x40, answer[:12].hex()
    size = 4 - ((answer[8] >> 2) & 3)
    return int.from_bytes(answer[12 : 12 + size], "little")


# --- item 1: a repeated mailbox write runs once -------------------------------------------------
def test_a_resent_write_with_the_same_counter_runs_once() -> None:
    """SOEM resends an FPWR of SM0 whose answer frame came late: the slave must not answer
    twice, or every later SDO answer is one behind (issue 16, item 1)."""
    esc, _ = make()
    preop(esc)
    slave = esc.slave
    assert isinstance(slave, MiniSlave)
    first = sdo_upload_request(0x1000, 0, counter=3)
    assert write_mailbox(esc, first)
    esc.service()  # the firmware took it; SM0 is empty again
    assert write_mailbox(esc, first)  # the resent frame: accepted by the ESC (WKC 1) ...
    esc.service()
    assert len(slave.requests) == 1  # ... but not executed again
    assert esc.mailbox_repeats == 1
    assert upload_value(read_mailbox(esc) or b"") == 0x00020192
    esc.service()
    assert read_mailbox(esc) is None  # one request, one answer
    # the next request gets its own answer, not the previous one
    assert write_mailbox(esc, sdo_upload_request(0x2000, 0, counter=4))
    esc.service()
    assert upload_value(read_mailbox(esc) or b"") == 0x1234


def test_counter_zero_and_a_new_counter_always_run() -> None:
    esc, _ = make()
    preop(esc)
    slave = esc.slave
    assert isinstance(slave, MiniSlave)
    for counter in (0, 0, 5, 6, 5):
        assert write_mailbox(esc, sdo_upload_request(0x2000, 0, counter=counter))
        esc.service()
        assert read_mailbox(esc) is not None
    assert len(slave.requests) == 5 and esc.mailbox_repeats == 0


def test_the_counter_memory_starts_again_with_the_mailbox() -> None:
    """A new master session (INIT, mailbox set up again) may start with the counter the
    previous session ended with."""
    esc, _ = make()
    preop(esc)
    slave = esc.slave
    assert isinstance(slave, MiniSlave)
    assert write_mailbox(esc, sdo_upload_request(0x2000, 0, counter=1))
    esc.service()
    assert read_mailbox(esc) is not None
    assert request(esc, AlState.INIT) == (AlState.INIT, 0)
    assert request(esc, AlState.PREOP) == (AlState.PREOP, 0)
    assert write_mailbox(esc, sdo_upload_request(0x2000, 0, counter=1))
    esc.service()
    assert read_mailbox(esc) is not None
    assert len(slave.requests) == 2


def test_a_lost_answer_comes_again_on_the_repeat_request() -> None:
    esc, _ = make()
    preop(esc)
    assert write_mailbox(esc, sdo_upload_request(0x2000, 0, counter=2))
    esc.service()
    first = read_mailbox(esc)
    assert first is not None  # read, but say the frame carrying it was lost
    activate = (esc.read(Reg.SM0 + 8 + 6, 1) or b"\0")[0]
    esc.write(Reg.SM0 + 8 + 6, bytes([activate ^ 0x02]))  # toggle the repeat request
    pdi = (esc.read(Reg.SM0 + 8 + 7, 1) or b"\0")[0]
    assert pdi & 0x02 == (activate ^ 0x02) & 0x02  # acknowledged
    assert read_mailbox(esc) == first


def test_a_bare_esc_keeps_a_mailbox_request_and_never_answers() -> None:
    """An EL2008 has no microcontroller: SMs the master sets up as a mailbox are plain
    buffers, nothing reads SM0 or fills SM1 (an outside check got mailbox error 2 from the
    EK1100, EL2008 and EL1809)."""
    from tests.drives.esc.test_registers import sm_bytes

    esc, _ = make(mailbox=False)
    assert esc.write(Reg.SM0, sm_bytes(SM0, SIZE, 0x26) + sm_bytes(SM1, SIZE, 0x22))
    assert request(esc, AlState.PREOP) == (AlState.PREOP, 0)
    assert write_mailbox(esc, sdo_upload_request(0x1018, 1, counter=1))
    for _ in range(3):
        esc.service()
        assert read_mailbox(esc) is None  # SM1 stays empty: no WKC
    assert not write_mailbox(esc, sdo_upload_request(0x1018, 1, counter=2))  # SM0 still full


# --- a real drive: SDO Information and emergencies ----------------------------------------------
def drive_esc() -> Esc:
    rx = (Pdo(0x1600, Direction.OUT, (PdoEntry(0x6040, 0, 16), PdoEntry(0x607A, 0, 32))),)
    tx = (
        Pdo(
            0x1A00,
            Direction.IN,
            (PdoEntry(0x6041, 0, 16), PdoEntry(0x6064, 0, 32), PdoEntry(0x60FD, 0, 32)),
        ),
    )
    drive = Cia402Drive(0, "GTHD", Identity(0x0000_0A1B, 0x0000_0001, 1), rx_pdos=rx, tx_pdos=tx)
    esc = Esc(drive, build_sii(sii_info_for(drive)), frame_time=FrameTime(0))
    configure(esc)
    assert request(esc, AlState.PREOP) == (AlState.PREOP, 0)
    return esc


def info_request(opcode: int, data: bytes, counter: int) -> bytes:
    body = struct.pack("<HBBH", 8 << 12, opcode, 0, 0) + data  # CoE service 8, info header
    return struct.pack("<HHBB", len(body), 0, 0, 3 | counter << 4) + body


def info_answers(esc: Esc, msg: bytes) -> list[bytes]:
    """Send one request and read every fragment the slave puts into SM1."""
    assert write_mailbox(esc, msg)
    out = []
    for _ in range(100):
        esc.service()
        got = read_mailbox(esc)
        if got is None:
            break
        length = struct.unpack_from("<H", got)[0]
        out.append(got[: 6 + length])
        if not got[8] & 0x80:  # Incomplete clear: the last fragment
            break
    return out


def test_get_od_list_is_fragmented_with_fragments_left() -> None:
    esc = drive_esc()
    frames = info_answers(esc, info_request(0x01, struct.pack("<H", 1), counter=1))
    assert len(frames) > 1, "a drive's dictionary does not fit one 128-byte mailbox"
    indices: list[int] = []
    for k, f in enumerate(frames):
        assert f[5] & 0x0F == 3 and struct.unpack_from("<H", f, 6)[0] >> 12 == 8
        opcode, left = f[8], struct.unpack_from("<H", f, 10)[0]
        assert opcode & 0x7F == 0x02
        assert left == len(frames) - 1 - k
        assert bool(opcode & 0x80) == (left > 0)
        data = f[12:]
        if k == 0:
            assert struct.unpack_from("<H", data)[0] == 1  # list type echoed first
            data = data[2:]
        indices += struct.unpack(f"<{len(data) // 2}H", data)
    drive = esc.slave
    assert isinstance(drive, Cia402Drive)
    assert indices == sorted(o.index for o in drive.od)
    assert {0x1000, 0x1018, 0x1600, 0x1A00, 0x6040, 0x6041, 0x607A} <= set(indices)


def test_get_od_list_lengths_and_pdo_lists() -> None:
    esc = drive_esc()
    (lengths,) = info_answers(esc, info_request(0x01, struct.pack("<H", 0), counter=1))
    counts = struct.unpack_from("<H5H", lengths, 12)
    assert counts[0] == 0 and counts[1] > counts[2] > 0 and counts[3] > 0
    rx = info_answers(esc, info_request(0x01, struct.pack("<H", 2), counter=2))
    rx_indices = [i for f in rx for i in struct.unpack(f"<{(len(f) - 12) // 2}H", f[12:])]
    assert 0x6040 in rx_indices[1:] and 0x6041 not in rx_indices[1:]


def test_object_and_entry_description() -> None:
    esc = drive_esc()
    (obj,) = info_answers(esc, info_request(0x03, struct.pack("<H", 0x1018), counter=1))
    assert obj[8] == 0x04
    index, dtype, max_sub, code = struct.unpack_from("<HHBB", obj, 12)
    length = struct.unpack_from("<H", obj)[0]
    assert (index, dtype, max_sub, code) == (0x1018, 0x0023, 4, 9)
    assert obj[18 : 6 + length] == b"Identity"  # the name is the rest, unpadded
    (entry,) = info_answers(esc, info_request(0x05, struct.pack("<HBB", 0x6040, 0, 7), counter=2))
    assert entry[8] == 0x06
    index, sub, vinfo, dtype, bits, access = struct.unpack_from("<HBBHHH", entry, 12)
    assert (index, sub, dtype, bits) == (0x6040, 0, 0x0006, 16)
    assert vinfo & 0x78 == 0  # SOEM asks for none of unit/default/min/max
    assert access & 0x0007 == 0x0007 and access & 0x0038 == 0x0038  # read/write in every state
    assert access & 0x0040 and not access & 0x0080  # RxPDO mappable only
    length = struct.unpack_from("<H", entry)[0]
    assert entry[22 : 6 + length].lower().startswith(b"controlword")
    (ro,) = info_answers(esc, info_request(0x05, struct.pack("<HBB", 0x1018, 1, 0), counter=3))
    assert struct.unpack_from("<H", ro, 20)[0] & 0x003F == 0x0007  # read-only
    (mx,) = info_answers(esc, info_request(0x05, struct.pack("<HBB", 0x6041, 0, 0x60), counter=4))
    assert mx[15] == 0x60 and struct.unpack_from("<HH", mx, 22) == (0, 0xFFFF)  # min, max


def test_sdo_info_errors_carry_the_abort_code() -> None:
    esc = drive_esc()
    cases = [
        (info_request(0x03, struct.pack("<H", 0x5555), 1), 0x06020000),
        (info_request(0x05, struct.pack("<HBB", 0x6040, 9, 0), 2), 0x06090011),
        (info_request(0x7E, b"", 3), 0x05040001),
    ]
    for msg, code in cases:
        (err,) = info_answers(esc, msg)
        assert err[8] & 0x7F == 0x07
        assert struct.unpack_from("<I", err, 12)[0] == code


def test_a_new_request_drops_unread_fragments() -> None:
    esc = drive_esc()
    assert write_mailbox(esc, info_request(0x01, struct.pack("<H", 1), counter=1))
    esc.service()
    assert read_mailbox(esc) is not None  # first fragment only
    assert write_mailbox(esc, sdo_upload_request(0x1018, 1, counter=2))
    for _ in range(3):
        esc.service()
    answer = read_mailbox(esc) or b""
    assert struct.unpack_from("<H", answer, 6)[0] >> 12 in (3, 8)
    if struct.unpack_from("<H", answer, 6)[0] >> 12 == 8:  # one fragment was already queued
        esc.service()
        answer = read_mailbox(esc) or b""
    assert upload_value(answer) == 0x0A1B


def test_a_fault_sends_a_coe_emergency() -> None:
    esc = drive_esc()
    drive = esc.slave
    assert isinstance(drive, Cia402Drive)
    code = drive.channel(0).inject_fault("following_error")
    drive.step(0, 1_000_000)
    esc.collect_emergencies()
    esc.service()
    msg = read_mailbox(esc)
    assert msg is not None
    assert msg[5] & 0x0F == 3 and struct.unpack_from("<H", msg, 6)[0] >> 12 == 1
    assert struct.unpack_from("<HB", msg, 8) == (code, 0x01)


@pytest.mark.parametrize(
    ("kind", "code", "register"),
    [
        ("overcurrent", 0x2310, 0x03),  # CiA 301 1001h: generic + current
        ("overvoltage", 0x3210, 0x05),  # generic + voltage
        ("undervoltage", 0x3220, 0x05),
        ("overtemperature", 0x4310, 0x09),  # generic + temperature
    ],
)
def test_the_emergency_frame_carries_the_error_register_of_the_code(
    kind: str, code: int, register: int
) -> None:
    esc = drive_esc()
    drive = esc.slave
    assert isinstance(drive, Cia402Drive)
    assert drive.channel(0).inject_fault(kind) == code
    drive.step(0, 1_000_000)
    esc.collect_emergencies()
    esc.service()
    msg = read_mailbox(esc)
    assert msg is not None
    assert struct.unpack_from("<HB", msg, 8) == (code, register)
    assert drive.od.upload(0x1001, 0) == bytes([register])


def test_emergencies_are_dropped_without_a_mailbox_state() -> None:
    esc = drive_esc()
    assert request(esc, AlState.INIT) == (AlState.INIT, 0)
    esc.slave.emit_emergency(0x8611, 0x01)
    esc.collect_emergencies()
    esc.service()
    assert not esc.slave.emergencies
    assert request(esc, AlState.PREOP) == (AlState.PREOP, 0)
    esc.service()
    assert read_mailbox(esc) is None


# --- FoE: what firmware-update code paths probe -------------------------------------------------
def foe(opcode: int, value: int, rest: bytes, counter: int) -> bytes:
    body = struct.pack("<BBI", opcode, 0, value) + rest
    return struct.pack("<HHBB", len(body), 0, 0, 4 | counter << 4) + body


def foe_answer(esc: Esc, msg: bytes) -> bytes | None:
    assert write_mailbox(esc, msg)
    esc.service()
    got = read_mailbox(esc)
    if got is None:
        return None
    assert got[5] & 0x0F == 4, got[:8].hex()
    return got[: 6 + struct.unpack_from("<H", got)[0]]


def test_foe_reads_a_small_file_in_acknowledged_packets() -> None:
    esc = drive_esc()
    content = bytes(range(256)) * 2  # 512 bytes: 5 packets of 116, the last one short
    esc.foe.files["log.txt"] = content
    got, counter = b"", 1
    answer = foe_answer(esc, foe(1, 0, b"log.txt", counter))
    packet = 1
    while answer is not None:
        opcode, _, number = struct.unpack_from("<BBI", answer, 6)
        assert (opcode, number) == (3, packet)
        chunk = answer[12:]
        got += chunk
        counter = counter % 7 + 1
        answer = foe_answer(esc, foe(4, number, b"", counter))
        packet += 1
        if len(chunk) < SIZE - 12:
            assert answer is None  # the ack of the short packet ends the read
    assert got == content


def test_foe_refuses_unknown_files_and_firmware_writes() -> None:
    esc = drive_esc()
    for opcode, counter, code in ((1, 1, 0x8001), (2, 2, 0x8002)):
        answer = foe_answer(esc, foe(opcode, 0, b"firmware.efw", counter))
        assert answer is not None
        assert struct.unpack_from("<BBI", answer, 6) == (5, 0, code)


def test_foe_not_found_for_a_name_as_long_as_the_mailbox_still_fits_it() -> None:
    """The error text echoes the name; a 110-byte name made a 184-byte answer for a 128-byte
    SM1 (outside check), and the master got mailbox error 7 instead of FoE 8001h."""
    esc = drive_esc()
    answer = foe_answer(esc, foe(1, 0, b"n" * (SIZE - 12), 1))
    assert answer is not None and len(answer) <= SIZE
    assert struct.unpack_from("<BBI", answer, 6) == (5, 0, 0x8001)
    assert answer[12:].startswith(b"no file 'nnn")


def test_a_repeat_request_after_the_next_fragment_came_puts_back_the_lost_one() -> None:
    """ETG.1000.4 5.6: the repeat request puts back the message the master read last. Here the
    slave has already put the next SDO Information fragment into SM1 when the master asks for
    the lost one: the lost fragment comes again, then the next one, none is skipped (an outside
    check found fragment 1 gone, and SOEM's slaveinfo reading fragment 2 as the list's start)."""
    reference = info_answers(drive_esc(), info_request(0x01, struct.pack("<H", 1), counter=1))
    assert len(reference) >= 2
    esc = drive_esc()
    assert write_mailbox(esc, info_request(0x01, struct.pack("<H", 1), counter=1))
    esc.service()
    lost = read_mailbox(esc)  # fragment 1 read; its frame never reached the master
    assert lost is not None and lost[:12] == reference[0][:12]
    esc.service()  # the firmware puts fragment 2 in at once
    activate = (esc.read(Reg.SM0 + 8 + 6, 1) or b"\0")[0]
    esc.write(Reg.SM0 + 8 + 6, bytes([activate ^ 0x02]))  # toggle the repeat request
    again = read_mailbox(esc)
    assert again == lost  # the same message, with its own link-layer counter
    got = [again[: 6 + struct.unpack_from("<H", again)[0]]]
    for _ in range(100):
        esc.service()
        frame = read_mailbox(esc)
        if frame is None:
            break
        got.append(frame[: 6 + struct.unpack_from("<H", frame)[0]])
        if not frame[8] & 0x80:
            break

    # every fragment once, in order (link-layer counters aside: byte 5 bits 4-6)
    def strip(f: bytes) -> bytes:
        return f[:5] + bytes([f[5] & 0x8F]) + f[6:]

    assert [strip(f) for f in got] == [strip(f) for f in reference]
