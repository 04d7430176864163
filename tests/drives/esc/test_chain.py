"""A chain of ESCs processing frames: addressing, working counters, logical mapping, robustness."""

from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.drives.esc import Chain, Command, Datagram, decode_frame, encode_frame
from gtecat.drives.esc.registers import Reg
from gtecat.drives.slave import AlState
from tests.conftest import examples
from tests.drives.esc.mini import (
    MiniMaster,
    mini_chain,
    sdo_download_request,
    sdo_upload_request,
)


def one(chain: Chain, d: Datagram) -> Datagram:
    raw = chain.exchange(encode_frame([d]))
    assert raw is not None
    return decode_frame(raw).datagrams[0]


def assign_addresses(m: MiniMaster, n: int) -> None:
    for pos in range(n):
        assert m.apwr(pos, Reg.STATION_ADDRESS, struct.pack("<H", 0x1001 + pos)) == 1


# --- addressing and working counters ----------------------------------------------------------
def test_brd_counts_every_slave_and_ors_their_data() -> None:
    chain = mini_chain(3)
    d = one(chain, Datagram(Command.BRD, 0, Reg.TYPE, bytes(2)))
    assert d.wkc == 3 and d.data == b"\x11\x00"
    assert d.adp == 3  # each slave increments the position field


def test_auto_increment_addresses_the_slave_that_sees_zero() -> None:
    chain = mini_chain(3)
    for pos in range(3):
        d = one(chain, Datagram(Command.APWR, (-pos) & 0xFFFF, Reg.STATION_ADDRESS, b"\x00\x20"))
        assert d.wkc == 1 and d.adp == (3 - pos) & 0xFFFF
        assert chain.escs[pos].station_address == 0x2000
        chain.escs[pos].write(Reg.STATION_ADDRESS, struct.pack("<H", 0x1001 + pos))
    assert one(chain, Datagram(Command.APRD, (-3) & 0xFFFF, 0, bytes(2))).wkc == 0  # no 4th slave


def test_configured_address_and_alias() -> None:
    chain = mini_chain(2)
    m = MiniMaster(chain)
    assign_addresses(m, 2)
    assert m.fprd(0x1002, Reg.STATION_ADDRESS, 2) == (b"\x02\x10", 1)
    assert m.fprd(0x1003, Reg.STATION_ADDRESS, 2)[1] == 0
    chain.escs[1].mem[Reg.STATION_ALIAS : Reg.STATION_ALIAS + 2] = b"\x07\x00"
    assert m.fprd(7, 0, 1)[1] == 0  # alias not enabled
    assert m.fpwr(0x1002, Reg.DL_ALIAS, b"\x01") == 1
    assert m.fprd(7, Reg.STATION_ADDRESS, 2) == (b"\x02\x10", 1)


@pytest.mark.parametrize(
    ("command", "wkc"),
    [
        (Command.APRD, 1),
        (Command.APWR, 1),
        (Command.APRW, 3),
        (Command.FPRD, 1),
        (Command.FPWR, 1),
        (Command.FPRW, 3),
        (Command.BRD, 3),
        (Command.BWR, 3),
        (Command.BRW, 9),
        (Command.NOP, 0),
    ],
)
def test_working_counter_rules(command: Command, wkc: int) -> None:
    chain = mini_chain(3)
    m = MiniMaster(chain)
    assign_addresses(m, 3)
    adp = {Command.FPRD: 0x1002, Command.FPWR: 0x1002, Command.FPRW: 0x1002}.get(command, 0xFFFF)
    d = one(chain, Datagram(command, adp, Reg.EVENT_MASK, b"\x04\x00"))
    assert d.wkc == wkc


def test_read_write_returns_the_old_value_and_stores_the_new() -> None:
    chain = mini_chain(1)
    chain.escs[0].write(Reg.EVENT_MASK, b"\x11\x00")
    d = one(chain, Datagram(Command.APRW, 0, Reg.EVENT_MASK, b"\x22\x00"))
    assert d.data == b"\x11\x00" and d.wkc == 3
    assert chain.escs[0].peek(Reg.EVENT_MASK, 2) == b"\x22\x00"


def test_frmw_reference_reads_the_others_write() -> None:
    chain = mini_chain(3)
    m = MiniMaster(chain)
    assign_addresses(m, 3)
    chain.escs[1].write(Reg.EVENT_MASK, b"\x5a\x00")
    d = one(chain, Datagram(Command.FRMW, 0x1002, Reg.EVENT_MASK, b"\x01\x00"))
    assert d.wkc == 3 and d.data == b"\x5a\x00"
    # the slave before the reference wrote what the master sent, the one after what it read
    assert chain.escs[0].peek(Reg.EVENT_MASK, 2) == b"\x01\x00"
    assert chain.escs[2].peek(Reg.EVENT_MASK, 2) == b"\x5a\x00"
    d = one(chain, Datagram(Command.ARMW, 0, Reg.EVENT_MASK, b"\x00\x00"))
    assert d.wkc == 3 and d.data == b"\x01\x00" and d.adp == 3


def test_irq_field_carries_unmasked_events() -> None:
    chain = mini_chain(2)
    m = MiniMaster(chain)
    assign_addresses(m, 2)
    m.fpwr(0x1002, Reg.EVENT_MASK, b"\x08\x00")  # AL status change
    d = one(chain, Datagram(Command.FPWR, 0x1001, Reg.AL_CONTROL, b"\x02\x00"))  # no mailbox SMs
    assert d.irq == 0  # slave 0 changed nothing the mask shows (its own mask is 0)
    one(chain, Datagram(Command.FPWR, 0x1002, Reg.AL_CONTROL, b"\x02\x00"))
    d = one(chain, Datagram(Command.NOP, 0, 0, b"\0"))
    assert d.irq & 0x0008


def test_source_address_comes_back_locally_administered() -> None:
    raw = mini_chain(1).exchange(encode_frame([Datagram(Command.BRD, data=b"\0")]))
    assert raw is not None and raw[6] & 0x02


# --- a whole SOEM-like start-up, in process ----------------------------------------------------
def test_scan_configure_and_run_in_op() -> None:
    chain = mini_chain(3)
    m = MiniMaster(chain)
    count = one(chain, Datagram(Command.BRD, 0, Reg.TYPE, bytes(2))).wkc
    assert count == 3
    assign_addresses(m, 3)
    identities = []
    for pos in range(3):
        word8 = m.eeprom_read(0x1001 + pos, 0x0008)
        identities.append(struct.unpack_from("<II", word8))
    assert identities == [(0x1234, 0x5678), (0x1234, 0x9999), (0x1234, 0x4444)]
    # slave 0 has a mailbox: SM0/SM1 from the SII words 0018h/001Ah
    mbx = struct.unpack("<HHHH", m.eeprom_read(0x1001, 0x0018))
    assert mbx == (0x1000, 128, 0x1080, 128)
    sm = struct.pack("<HHBBBB", 0x1000, 128, 0x26, 0, 1, 0) + struct.pack(
        "<HHBBBB", 0x1080, 128, 0x22, 0, 1, 0
    )
    m.fpwr(0x1001, Reg.SM0, sm)
    for pos in range(3):
        assert m.set_state(0x1001 + pos, AlState.PREOP) == (2, 0)
    # SDO through the mailbox
    answer = m.mailbox_sdo(0x1001, sdo_upload_request(0x2000, 0))
    assert answer[8] == 0x4B and answer[12:14] == b"\x34\x12"
    answer = m.mailbox_sdo(0x1001, sdo_download_request(0x2000, 0, b"\x99\x00", 2))
    assert answer[8] == 0x60
    answer = m.mailbox_sdo(0x1001, sdo_upload_request(0x7777, 0, 3))
    assert answer[7] >> 4 == 2 and answer[8] == 0x80
    assert struct.unpack_from("<I", answer, 12)[0] == 0x06020000
    # process data: outputs 0..5 (slave 0) 6..7 (slave 1) 8.0-8.1 (slave 2), inputs after
    fm = struct.Struct("<IHBBHBBB3x")
    m.fpwr(0x1001, Reg.SM0 + 16, struct.pack("<HHBBBB", 0x1100, 6, 0x64, 0, 1, 0))
    m.fpwr(0x1001, Reg.SM0 + 24, struct.pack("<HHBBBB", 0x1400, 10, 0x20, 0, 1, 0))
    m.fpwr(
        0x1001,
        Reg.FMMU0,
        fm.pack(0, 6, 0, 7, 0x1100, 0, 2, 1) + fm.pack(9, 10, 0, 7, 0x1400, 0, 1, 1),
    )
    m.fpwr(0x1002, Reg.SM0, struct.pack("<HHBBBB", 0x1000, 2, 0x64, 0, 1, 0))
    m.fpwr(0x1002, Reg.SM0 + 8, struct.pack("<HHBBBB", 0x1400, 2, 0x20, 0, 1, 0))
    m.fpwr(
        0x1002,
        Reg.FMMU0,
        fm.pack(6, 2, 0, 7, 0x1000, 0, 2, 1) + fm.pack(19, 2, 0, 7, 0x1400, 0, 1, 1),
    )
    m.fpwr(0x1003, Reg.SM0, struct.pack("<HHBBBB", 0x1000, 1, 0x64, 0, 1, 0))
    m.fpwr(0x1003, Reg.SM0 + 8, struct.pack("<HHBBBB", 0x1400, 1, 0x20, 0, 1, 0))
    m.fpwr(
        0x1003,
        Reg.FMMU0,
        fm.pack(8, 1, 0, 1, 0x1000, 0, 2, 1) + fm.pack(21, 1, 0, 2, 0x1400, 0, 1, 1),
    )
    for pos in range(3):
        assert m.set_state(0x1001 + pos, AlState.SAFEOP) == (4, 0)
    image = bytearray(22)
    image[:6] = b"\x01\x02\x03\x04\x05\x06"
    image[6:8] = b"\xab\xcd"
    image[8] = 0b11
    assert m.lrw(0, bytes(image))[1] == 3  # SAFEOP: inputs only
    for pos in range(3):
        assert m.set_state(0x1001 + pos, AlState.OP) == (8, 0)
    for cycle in range(3):
        data, wkc = m.lrw(0, bytes(image))
        assert wkc == 9
        chain.step(cycle * 1_000_000, 1_000_000)
    assert data[9:15] == b"\x01\x02\x03\x04\x05\x06"  # slave 0 echoes its outputs
    assert data[19:21] == b"\xab\xcd"
    assert data[21] & 0b111 == 0b011  # slave 2: 2 bits echoed, third bit = step count LSB
    assert chain.stats.process_data_frames >= 4


# --- robustness -----------------------------------------------------------------------------------
def test_malformed_frames_are_dropped_and_counted() -> None:
    chain = mini_chain(2)
    good = bytearray(encode_frame([Datagram(Command.BWR, 0, Reg.EVENT_MASK, b"\x01\x00")]))
    truncated = good[:20]
    assert not chain.process(truncated)
    wrong_len = bytearray(good)
    struct.pack_into("<H", wrong_len, 14, (1 << 12) | 0x7FF)
    assert not chain.process(wrong_len)
    not_ecat = bytearray(good)
    not_ecat[12:14] = b"\x08\x00"
    assert not chain.process(not_ecat)
    assert chain.stats.dropped == 2 and chain.stats.ignored == 1
    assert chain.escs[0].peek(Reg.EVENT_MASK, 2) == b"\x00\x00"  # nothing half-done
    assert chain.process(good) and chain.stats.frames == 1


commands = st.sampled_from(list(Command))


@settings(max_examples=examples(300, 40), deadline=None)
@given(
    st.lists(
        st.builds(
            Datagram,
            command=commands,
            adp=st.integers(0, 0xFFFF),
            ado=st.one_of(
                st.integers(0, 0xFFFF),
                st.sampled_from([0x0120, 0x0502, 0x0600, 0x0800, 0x0900, 0x0910, 0x1000]),
            ),
            data=st.binary(max_size=64),
        ),
        min_size=1,
        max_size=5,
    )
)
def test_any_well_formed_frame_is_answered_and_nothing_raises(dgs: list[Datagram]) -> None:
    chain = mini_chain(3)
    for _ in range(2):
        raw = chain.exchange(encode_frame(dgs))
        assert raw is not None
        chain.service()
        chain.step(0, 1_000_000)
        chain.poll()
    assert chain.stats.errors == 0
    back = decode_frame(raw).datagrams
    assert [d.command for d in back] == [d.command for d in dgs]


@settings(max_examples=examples(300, 40), deadline=None)
@given(st.binary(min_size=0, max_size=200))
def test_garbage_never_raises(raw: bytes) -> None:
    chain = mini_chain(2)
    buf = bytearray(raw)
    if len(buf) >= 14:
        buf[12:14] = b"\x88\xa4"
    chain.process(buf)
    assert chain.stats.errors == 0
    assert chain.stats.frames + chain.stats.dropped + chain.stats.ignored == 1


def test_mailbox_state_polled_through_a_bit_fmmu() -> None:
    """TwinCAT maps bit 3 of SM1's status (080Dh) into the image to poll every mailbox at once."""
    chain = mini_chain(1)
    m = MiniMaster(chain)
    assign_addresses(m, 1)
    sm = struct.pack("<HHBBBB", 0x1000, 128, 0x26, 0, 1, 0) + struct.pack(
        "<HHBBBB", 0x1080, 128, 0x22, 0, 1, 0
    )
    m.fpwr(0x1001, Reg.SM0, sm)
    assert m.set_state(0x1001, AlState.PREOP) == (2, 0)
    # FMMU 2: logical 0x8000 bit 0 <- physical 080Dh bit 3, read
    m.fpwr(0x1001, Reg.FMMU0 + 32, struct.pack("<IHBBHBBB3x", 0x8000, 1, 0, 0, 0x080D, 3, 1, 1))

    def poll() -> int:
        d = m.frame([Datagram.logical(Command.LRD, 0x8000, b"\x00")])[0]
        assert d.wkc == 1
        return d.data[0] & 1

    assert poll() == 0
    req = sdo_upload_request(0x2000, 0)
    assert m.fpwr(0x1001, 0x1000, req + bytes(128 - len(req))) == 1  # service() runs after it
    assert poll() == 1
    assert m.fprd(0x1001, 0x1080, 128)[1] == 1
    assert poll() == 0


def test_split_image_with_lrd_and_lwr() -> None:
    """Masters that may not use LRW send inputs with LRD and outputs with LWR (SOEM blockLRW)."""
    chain = mini_chain(1)
    esc = chain.escs[0]
    esc.write(Reg.SM0, struct.pack("<HHBBBB", 0x1000, 128, 0x26, 0, 1, 0))
    esc.write(Reg.SM0 + 8, struct.pack("<HHBBBB", 0x1080, 128, 0x22, 0, 1, 0))
    esc.write(Reg.SM0 + 16, struct.pack("<HHBBBB", 0x1100, 6, 0x64, 0, 1, 0))
    esc.write(Reg.SM0 + 24, struct.pack("<HHBBBB", 0x1400, 10, 0x20, 0, 1, 0))
    fm = struct.Struct("<IHBBHBBB3x")
    esc.write(
        Reg.FMMU0, fm.pack(0, 6, 0, 7, 0x1100, 0, 2, 1) + fm.pack(6, 10, 0, 7, 0x1400, 0, 1, 1)
    )
    for state in (2, 4, 8):
        esc.write(Reg.AL_CONTROL, bytes([state, 0]))
    esc.slave.tx[:] = bytes(range(10))
    esc.load_inputs()
    out = one(chain, Datagram.logical(Command.LWR, 0, b"\x09" * 6))
    assert out.wkc == 1 and bytes(esc.slave.rx) == b"\x09" * 6
    inp = one(chain, Datagram.logical(Command.LRD, 6, bytes(10)))
    assert inp.wkc == 1 and inp.data == bytes(range(10))
