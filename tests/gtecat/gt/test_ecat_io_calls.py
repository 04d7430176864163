"""A controller output wired to EtherCAT bits, as field code does it (vendor GTN header):
``GTN_RelateEcatSlaveToMcGpoBit(core, 1, axisIndex, 1, 16, 0)`` maps a drive's 60FEh bit 16
(its brake or DO0) to general-purpose output 1, ``(core, 2, slave, 0, 7, 1)`` bit 7 of byte
1 of an IO slave to output 2; the application then switches them with ``GTN_SetDoBit``.
Checked from the field side: the drive's received 60FEh and the slave's output byte."""

from __future__ import annotations

from ctypes import byref, c_char, c_ubyte, c_ulong

from gtecat import gt

from .conftest import bring_up


def io_output(slave: int, offset: int) -> int:
    b = (c_ubyte * 1)()
    assert gt.GT_EcatIOReadInput(slave, offset, 1, b) == 0
    return b[0]


def drive_do() -> int:
    v = c_ulong()
    assert gt.GT_GetEcatAxisDO(1, byref(v)) == 0
    return v.value


def test_gpo_bits_drive_a_servo_output_and_an_io_slave_bit():
    bring_up("full_servo.eni", clock="lockstep")
    assert gt.GTN_RelateEcatSlaveToMcGpoBit(1, 1, 0, 1, 16, 0) == 0, gt.GTE_GetLastError()
    assert gt.GTN_RelateEcatSlaveToMcGpoBit(1, 2, 1, 0, 7, 1) == 0, gt.GTE_GetLastError()
    assert gt.GTN_SetDoBit(1, gt.MC_GPO, 1, 1) == 0 and gt.GTN_SetDoBit(1, gt.MC_GPO, 2, 1) == 0
    gt.GTE_Wait(2)
    assert drive_do() >> 16 & 1 and io_output(1, 1) & 0x80
    value = c_char()
    assert gt.GTN_GetEcatAxisDOBit(1, 1, 16, byref(value)) == 0 and value.value == b"\x01"
    ch = gt.GTE_Slave(0).channel(0)
    assert ch.digital_outputs >> 16 & 1  # what the drive received
    assert gt.GTN_SetDo(1, gt.MC_GPO, 0) == 0
    gt.GTE_Wait(2)
    assert not drive_do() >> 16 & 1 and not io_output(1, 1) & 0x80
    assert gt.GTN_GetEcatAxisDOBit(1, 1, 16, byref(value)) == 0 and value.value == b"\x00"


def test_bad_relations_are_refused_at_the_call():
    bring_up("full_servo.eni", clock="lockstep")
    assert gt.GT_RelateEcatSlaveToMcGpoBit(17, 1, 0, 0, 0) == 7  # 16 general-purpose outputs
    assert gt.GT_RelateEcatSlaveToMcGpoBit(1, 1, 0, 8, 0) == 7  # a bit of a byte
    assert gt.GT_RelateEcatSlaveToMcGpoBit(1, 1, 0, 0, 2) == 7  # two output bytes
    assert gt.GT_RelateEcatSlaveToMcGpoBit(1, 1, 2, 0, 0) == 7  # no third type
    assert gt.GT_RelateEcatSlaveToMcGpoBit(1, 5, 1, 0, 0) == 7  # one axis
    assert gt.GT_GetEcatAxisDOBit(1, 32, byref(c_char())) == 7
