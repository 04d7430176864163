"""A slave without a mailbox is a bare ESC: no firmware checks, SMs where the device has them.

TwinCAT's own ENI for an EL2008 writes the output SM (at the digital output
register 0F00h) only at SAFEOP -> OP and requests SAFEOP before (issue 16,
item 2); a real EL2008 takes it, since no firmware looks at its SMs.
"""

from __future__ import annotations

import struct

from gtecat.drives.esc.registers import Esc, FrameTime, Reg
from gtecat.drives.esc.sii import build_sii, sii_info_for
from gtecat.drives.io_slaves import IoSlave
from gtecat.drives.slave import AlState
from gtecat.eni.model import Direction, Identity, Pdo, PdoEntry
from tests.drives.esc.test_registers import make, request


def el2008() -> Esc:
    pdos = tuple(
        Pdo(0x1600 + k, Direction.OUT, (PdoEntry(0x7000 + 0x10 * k, 1, 1, "Output", "BOOL"),))
        for k in range(8)
    )
    slave = IoSlave(1, "Term 2 (EL2008)", Identity(2, 0x07D83052, 0x00120000), rx_pdos=pdos)
    return Esc(slave, build_sii(sii_info_for(slave)), frame_time=FrameTime(0))


def test_twincat_order_for_an_el2008_reaches_op() -> None:
    esc = el2008()
    assert esc.read(Reg.PDI_CONTROL, 2) == b"\x04\x01"  # digital I/O, device emulation
    assert esc.write(0x0800, bytes(8))  # IP: clear sms
    assert request(esc, AlState.PREOP) == (AlState.PREOP, 0)
    fmmu = struct.pack("<IHBBHBBB3x", 0x01000004, 1, 0, 7, 0x0F00, 0, 2, 1)
    assert esc.write(0x0600, fmmu)  # PS: set fmmu 0 (outputs), no SM yet
    assert request(esc, AlState.SAFEOP) == (AlState.SAFEOP, 0)
    assert esc.write(0x0800, bytes.fromhex("000f010044000100"))  # SO: set sm 0 (outputs)
    assert request(esc, AlState.OP) == (AlState.OP, 0)
    data = bytearray(b"\xa5")
    assert esc.logical(11, 0x01000004, data) == 1  # LWR through the FMMU into SM0 at 0F00h
    assert esc.slave.rx == bytearray(b"\xa5")
    assert esc.peek(0x0F00, 1) == b"\xa5"


def test_a_slave_with_firmware_still_checks_its_sms() -> None:
    esc, _ = make()  # a mailbox slave: a microcontroller checks the SM layout
    assert esc.write(Reg.SM0, struct.pack("<HHBBBB", 0x1000, 128, 0x26, 0, 1, 0))
    assert esc.write(Reg.SM0 + 8, struct.pack("<HHBBBB", 0x1080, 128, 0x22, 0, 1, 0))
    assert request(esc, AlState.PREOP) == (AlState.PREOP, 0)
    status, code = request(esc, AlState.SAFEOP)
    assert status == AlState.PREOP | 0x10 and code == 0x001D  # no output SM: refused
