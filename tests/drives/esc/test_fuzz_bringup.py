"""The wire slave after hostile datagrams: random chains of datagrams (seeded, bounded; more
with GTECAT_LONG=N), then a legitimate master's bring-up as SOEM does it (reset what a
previous master may have left: alias, loop control, FMMUs, SMs, EEPROM ownership, INIT),
which must read every slave's identity from the EEPROM and reach OP with the right working
counters.  The fuzz leaves out the one thing a real ESC accepts that changes the EEPROM - a
write command with its write-enable bit in the same datagram - so the identity must survive
everything else."""

from __future__ import annotations

import os
import random
import struct

from gtecat.drives.esc import Command, Datagram, encode_frame
from gtecat.drives.esc.registers import Reg
from gtecat.drives.slave import AlState

from .mini import MiniMaster, mini_chain

#: 300 frames by default; GTECAT_LONG=N: N x 25,000 (the outside check's campaign)
CHAINS = 25_000 * int(os.environ.get("GTECAT_LONG") or 0) or 300
#: registers worth hitting more often than the rest of the 4 KiB register space
HOT = [0x0010, 0x0012, 0x0100, 0x0101, 0x0103, 0x0120, 0x0200, 0x0400, 0x0420, 0x0500,
       0x0501, 0x0502, 0x0503, 0x0504, 0x0508, 0x0600, 0x0610, 0x0800, 0x0808, 0x0810,
       0x0900, 0x0910, 0x0920, 0x0980, 0x1000, 0x1080]  # fmt: skip
IDENTITIES = [(0x1234, 0x5678), (0x1234, 0x9999), (0x1234, 0x4444)]


def _accepted_eeprom_write(ado: int, data: bytes) -> bool:
    """The datagram writes 0502h-0503h with write enable and the write command together."""
    if not ado <= 0x0502 < ado + len(data) - 1:
        return False
    lo, hi = data[0x0502 - ado], data[0x0503 - ado]
    return bool(lo & 0x01) and bool(hi & 0x02)


def _datagram(rng: random.Random) -> Datagram:
    command = rng.choice(list(Command))
    ado = (
        rng.choice(HOT) + rng.choice([0, 0, 0, 1, 2, 3])
        if rng.random() < 0.8
        else rng.randrange(0x1100)
    )
    n = rng.choice([1, 2, 4, 8, 16, rng.randrange(1, 64)])
    data = bytes(rng.getrandbits(8) for _ in range(n))
    if command in (
        Command.APWR,
        Command.FPWR,
        Command.BWR,
        Command.APRW,
        Command.FPRW,
        Command.BRW,
        Command.ARMW,
        Command.FRMW,
    ) and _accepted_eeprom_write(ado, data):
        data = bytes(b & 0xFE if i == 0x0502 - ado else b for i, b in enumerate(data))  # fmt: skip
    if command in (Command.LRD, Command.LWR, Command.LRW):
        return Datagram.logical(
            command, rng.randrange(1 << 32) if rng.random() < 0.3 else rng.randrange(64), data
        )
    adp = rng.choice([0, 0xFFFF, 0xFFFE, 0x1001, 0x1002, 0x1003, rng.randrange(0x10000)])
    return Datagram(command, adp, ado, data, rng.randrange(256))


def bring_up(m: MiniMaster, n: int) -> list[tuple[int, int]]:
    """SOEM's ecx_config_init resets, then scan, identity, mailbox SM, states to OP."""
    bwr = lambda ado, data: m.cmd(Command.BWR, 0, ado, data)  # noqa: E731
    bwr(0x0101, b"\x00")  # DL port: no manual loop
    bwr(0x0103, b"\x00")  # ignore alias
    bwr(Reg.AL_CONTROL, struct.pack("<H", AlState.INIT | 0x10))  # INIT, acknowledge errors
    bwr(0x0200, b"\x00\x00")
    bwr(0x0300, bytes(8))
    bwr(0x0600, bytes(256))  # FMMUs
    bwr(0x0800, bytes(128))  # SMs
    bwr(0x0981, b"\x00")  # DC activation
    bwr(0x0910, bytes(8))
    bwr(0x0500, b"\x02")  # EEPROM: forced to the master
    bwr(0x0500, b"\x00")
    for pos in range(n):
        assert m.apwr(pos, Reg.STATION_ADDRESS, struct.pack("<H", 0x1001 + pos)) == 1
    identities = []
    for pos in range(n):
        identities.append(struct.unpack_from("<II", m.eeprom_read(0x1001 + pos, 0x0008)))
    mbx = struct.unpack("<HHHH", m.eeprom_read(0x1001, 0x0018))
    sm = struct.pack("<HHBBBB", mbx[0], mbx[1], 0x26, 0, 1, 0) + struct.pack(
        "<HHBBBB", mbx[2], mbx[3], 0x22, 0, 1, 0
    )
    m.fpwr(0x1001, Reg.SM0, sm)
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
    for state in (AlState.PREOP, AlState.SAFEOP, AlState.OP):
        for pos in range(n):
            got = m.set_state(0x1001 + pos, state)
            assert got == (int(state), 0), (pos, state, got)
    image = bytes(22)
    for cycle in range(3):
        _, wkc = m.lrw(0, image)
        assert wkc == 9
        m.chain.step(cycle * 1_000_000, 1_000_000)
    return identities


def test_a_legitimate_master_reaches_op_after_random_datagrams() -> None:
    rng = random.Random(2626)
    chain = mini_chain(3)
    m = MiniMaster(chain)
    assert bring_up(m, 3) == IDENTITIES
    sii = [bytes(esc.sii) for esc in chain.escs]
    for k in range(CHAINS):
        frame = encode_frame([_datagram(rng) for _ in range(rng.randrange(1, 6))])
        chain.exchange(frame)
        chain.service()
        if k % 7 == 0:
            chain.step(k * 1_000_000, 1_000_000)
    assert [bytes(esc.sii) for esc in chain.escs] == sii
    assert bring_up(m, 3) == IDENTITIES
