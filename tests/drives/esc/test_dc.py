"""Distributed clocks as a master sees them: receive times, system time, offset, delay, the
drift compensation's ARMW/FRMW, and the compiled DC datagrams equal to the register path.

The master's side is written out here the way SOEM's ``ec_configdc`` does it (latch with a
BWR of 0900h, read the receive times, offset = master time - local time, delay = half the
difference of the loop times), with raw datagrams; every frame carries an explicit arrival
time, so each expected value is exact.
"""

from __future__ import annotations

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.drives.esc import Chain, Command, Datagram, decode_frame, encode_frame
from gtecat.drives.esc.registers import HOP_NS
from gtecat.drives.slave import AlState
from tests.conftest import examples
from tests.drives.esc.test_plan import configured

STATIONS = (0x1001, 0x1002, 0x1003)
MASTER_TIME = 800_000_000_123_456_789  #: the master's clock when it set the offsets (ns)
T_LATCH = 5_000_000_000  #: arrival time of the latch frame at the first slave
M64 = (1 << 64) - 1


def send(chain: Chain, datagrams: list[Datagram], t_ns: int) -> list[Datagram]:
    buf = bytearray(encode_frame(datagrams))
    assert chain.process(buf, t_ns=t_ns)
    chain.service()
    return decode_frame(bytes(buf)).datagrams


def u64(chain: Chain, station: int, ado: int, t_ns: int) -> int:
    d = send(chain, [Datagram(Command.FPRD, station, ado, bytes(8))], t_ns)[0]
    assert d.wkc == 1
    return struct.unpack("<Q", d.data)[0]


def configure_dc(chain: Chain) -> list[int]:
    """``ec_configdc`` on the three-slave line; the delays it wrote."""
    assert send(chain, [Datagram(Command.BWR, 0, 0x0900, bytes(4))], T_LATCH)[0].wkc == 3
    t = T_LATCH + 1_000_000
    loops, delays = [], []
    for station in STATIONS:
        raw = send(chain, [Datagram(Command.FPRD, station, 0x0900, bytes(8))], t)[0].data
        t_a, t_b = struct.unpack("<II", raw)
        loops.append((t_b - t_a) & 0xFFFFFFFF if t_b else 0)
        local = u64(chain, station, 0x0918, t)
        offset = (MASTER_TIME - local) & M64
        send(chain, [Datagram(Command.FPWR, station, 0x0920, struct.pack("<Q", offset))], t)
        delays.append((loops[0] - loops[-1]) // 2)
        send(chain, [Datagram(Command.FPWR, station, 0x0928, struct.pack("<I", delays[-1]))], t)
    return delays


def dc_chain() -> Chain:
    chain, master = configured(False)
    for station in STATIONS:
        assert master.set_state(station, AlState.OP) == (8, 0)
    return chain


def test_receive_times_offsets_and_delays_are_those_of_a_line() -> None:
    chain = dc_chain()
    assert send(chain, [Datagram(Command.BWR, 0, 0x0900, bytes(4))], T_LATCH)[0].wkc == 3
    for pos, station in enumerate(STATIONS):
        t_a, t_b = struct.unpack("<II", struct.pack("<Q", u64(chain, station, 0x0900, T_LATCH)))
        local = u64(chain, station, 0x0918, T_LATCH)  # the latch's time, 64 bit
        assert t_a == local & 0xFFFFFFFF
        # port 1 sees the frame come back after the rest of the line, both ways; the last
        # slave's port 1 is closed
        assert t_b == (0 if pos == 2 else (t_a + 2 * (2 - pos) * HOP_NS) & 0xFFFFFFFF)
    chain = dc_chain()
    delays = configure_dc(chain)
    assert delays == [0, HOP_NS, 2 * HOP_NS]  # each hop's forwarding time from the reference
    t = T_LATCH + 3_000_000
    for station, delay in zip(STATIONS, delays, strict=True):
        assert struct.unpack("<I", struct.pack("<Q", u64(chain, station, 0x0928, t))[:4])[0] == (
            delay
        )


def test_system_time_runs_with_the_frames_clock_from_the_masters_time() -> None:
    chain = dc_chain()
    configure_dc(chain)
    for t in (T_LATCH + 2_000_000, T_LATCH + 2_000_000 + 1, T_LATCH + 1_002_000_000):
        for station in STATIONS:
            # every slave's clock was set to the master's time at the latch, at its own port
            assert u64(chain, station, 0x0910, t) == MASTER_TIME + (t - T_LATCH)


def test_armw_distributes_the_reference_time_and_the_difference_settles() -> None:
    chain = dc_chain()
    configure_dc(chain)
    expected_wkc = 1 + 2  # the reference reads, the two others write
    for cycle in range(4):
        t = T_LATCH + 10_000_000 + cycle * 1_000_000
        lrw = Datagram.logical(Command.LRW, 0, bytes(8))  # the byte-aligned outputs
        armw = Datagram(Command.ARMW, 0, 0x0910, bytes(8))
        _lrw, got = send(chain, [lrw, armw], t)
        assert got.wkc == expected_wkc
        assert struct.unpack("<Q", got.data)[0] == MASTER_TIME + (t - T_LATCH)
        assert got.adp == 3  # auto-increment: each slave counted it
        diffs = [u64(chain, s, 0x092C, t) & 0xFFFFFFFF for s in STATIONS]
        if cycle == 0:
            # the others were behind by their delay: ahead of the local copy (bit 31 set)
            assert diffs == [0, 0x80000000 | HOP_NS, 0x80000000 | 2 * HOP_NS]
        else:
            assert diffs == [0, 0, 0]
        # now all clocks show one time: a frame reaching slave k later by k hops reads more
        for pos, station in enumerate(STATIONS):
            assert u64(chain, station, 0x0910, t + 7) == MASTER_TIME + (t + 7 - T_LATCH) + (
                pos * HOP_NS
            )
    # the LRW + ARMW frame took the compiled path, the ARMW's plan locked on its constants
    assert chain._multi is not None
    armw_plan = chain._dc_plans[(Command.ARMW, 0, 0x0910, 8)]
    assert armw_plan is not None and armw_plan.gen == chain._dc_gen


def test_frmw_of_the_reference_and_a_32_bit_write_do_the_same() -> None:
    chain = dc_chain()
    configure_dc(chain)
    t = T_LATCH + 20_000_000
    got = send(chain, [Datagram(Command.FRMW, STATIONS[0], 0x0910, bytes(4))], t)[0]
    assert got.wkc == 3
    assert struct.unpack("<I", got.data)[0] == (MASTER_TIME + (t - T_LATCH)) & 0xFFFFFFFF
    assert u64(chain, STATIONS[2], 0x0910, t) == MASTER_TIME + (t - T_LATCH) + 2 * HOP_NS


def test_brd_of_the_system_time_ors_every_clock() -> None:
    chain = dc_chain()
    configure_dc(chain)
    for cycle in range(3):
        t = T_LATCH + 30_000_000 + cycle * 1000
        got = send(chain, [Datagram(Command.BRD, 0, 0x0910, bytes(8))], t)[0]
        assert got.wkc == 3
        want = 0
        for station in STATIONS:
            want |= u64(chain, station, 0x0910, t)
        assert struct.unpack("<Q", got.data)[0] == want


def test_sync0_activated_as_ec_dcsync0_does_reads_its_next_pulse() -> None:
    """SOEM's ``ec_dcsync0(slave, TRUE, 1 ms, 0)``: deactivate, read the system time, start
    100 ms ahead on a cycle boundary, cycle 1 ms, activate; 0990h then reads the system time
    of the next SYNC0 pulse, 098Eh bit 0 once one came. ``ec_dcsync01`` adds SYNC1."""
    chain = dc_chain()
    configure_dc(chain)
    station, cycle = STATIONS[1], 1_000_000
    t = T_LATCH + 40_000_000

    def fpwr(ado: int, data: bytes) -> None:
        assert send(chain, [Datagram(Command.FPWR, station, ado, data)], t)[0].wkc == 1

    fpwr(0x0981, b"\0")
    fpwr(0x0980, b"\0")
    now = u64(chain, station, 0x0910, t)
    start = ((now + 100_000_000) // cycle) * cycle + cycle
    fpwr(0x0990, struct.pack("<Q", start))
    fpwr(0x09A0, struct.pack("<I", cycle))
    fpwr(0x09A4, struct.pack("<I", 300_000))  # SYNC1 300 us after each SYNC0
    fpwr(0x0981, b"\x07")  # cyclic operation, SYNC0, SYNC1
    assert u64(chain, station, 0x0990, t) == start  # not yet: the first pulse is the start
    assert send(chain, [Datagram(Command.FPRD, station, 0x098E, bytes(2))], t)[0].data == bytes(2)
    later = t + (start - now) + 3 * cycle + cycle // 2  # 3.5 cycles after the start
    assert u64(chain, station, 0x0990, later) == start + 4 * cycle
    assert u64(chain, station, 0x0998, later) == start + 4 * cycle + 300_000
    assert send(chain, [Datagram(Command.FPRD, station, 0x098E, bytes(2))], later)[0].data == (
        b"\x01\x01"
    )
    t = later
    fpwr(0x0981, b"\0")  # deactivated: the start time reads back as written
    assert u64(chain, station, 0x0990, later) == start


# --- the compiled DC datagrams answer exactly what the register path answers ---------------------
def _general_only(chain: Chain) -> Chain:
    chain._dc_plan = lambda *key: None  # type: ignore[method-assign]
    return chain


frames = st.sampled_from(
    [
        ("lrw+armw", 8),
        ("lrw+frmw", 8),
        ("lrw+frmw", 4),
        ("lrw+brd", 8),
        ("fprd", 8),
        ("fprd1", 8),  # after "twin": two slaves answer to this address
        ("twin", 0),  # the third slave takes the second's station address
        ("frmw2", 8),  # FRMW of the second slave: the first writes the master's bytes
        ("offset", 0),  # the master sets a new offset (the compiled plans must notice)
        ("write", 0),  # the master writes a system time itself (first slave only)
        ("step", 0),
    ]
)


@settings(max_examples=examples(25, 10), deadline=None)
@given(st.lists(st.tuples(frames, st.integers(0, 3_000)), min_size=1, max_size=30))
@pytest.mark.long
def test_compiled_dc_datagrams_answer_like_the_registers(sequence: list) -> None:
    fast = dc_chain()
    slow = _general_only(dc_chain())
    for chain in (fast, slow):
        configure_dc(chain)
    t = T_LATCH + 50_000_000
    for (kind, size), jitter in sequence:
        t += 1_000_000 + jitter
        if kind == "step":
            for chain in (fast, slow):
                chain.step(t, 1_000_000)
            continue
        if kind == "offset":
            dgs = [Datagram(Command.FPWR, STATIONS[1], 0x0920, struct.pack("<q", jitter))]
        elif kind == "write":
            dgs = [Datagram(Command.FPWR, STATIONS[0], 0x0910, struct.pack("<Q", t * 3))]
        elif kind == "fprd":
            dgs = [Datagram(Command.FPRD, STATIONS[2], 0x0910, bytes(size))]
        elif kind == "fprd1":
            dgs = [Datagram(Command.FPRD, STATIONS[1], 0x0910, bytes(size))]
        elif kind == "twin":
            dgs = [Datagram(Command.APWR, (-2) & 0xFFFF, 0x0010, struct.pack("<H", STATIONS[1]))]
        else:
            cmd, adp = {
                "lrw+armw": (Command.ARMW, 0),
                "lrw+frmw": (Command.FRMW, STATIONS[0]),
                "lrw+brd": (Command.BRD, 0),
                "frmw2": (Command.FRMW, STATIONS[1]),
            }[kind]
            dgs = [
                Datagram.logical(Command.LRW, 0, bytes([jitter & 0xFF]) * 22),
                Datagram(cmd, adp, 0x0910, (t // 7).to_bytes(8, "little")[:size]),
            ]
        assert send(fast, dgs, t) == send(slow, dgs, t), kind
    for ef, es in zip(fast.escs, slow.escs, strict=True):
        # 0910h in memory is only where a read packs the time it answers: not compared
        assert ef.mem[0x0900:0x0910] == es.mem[0x0900:0x0910]
        assert ef.mem[0x0918:0x0A00] == es.mem[0x0918:0x0A00]
        assert ef.system_time(t) == es.system_time(t)
