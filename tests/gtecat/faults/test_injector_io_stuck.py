"""A stuck IO input is released when its fault ends (gtecat.faults.injector, module
docstring): the input then reads what the field puts there now, the value it had before the
fault unless something else set it meanwhile.  Read through GT calls, as an application
sees it."""

from __future__ import annotations

from ctypes import byref, c_long, c_short, c_ubyte

from gtecat import faults, gt
from tests.conftest import EXAMPLES

SLAVE, BIT = 2, 3  # manual figure 5-2: slave 2 is the IO slave, 2 output then 2 input bytes


def up() -> None:
    assert gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), log="") == 0
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    st = c_short()
    for _ in range(10_000):
        if gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1:
            break
    assert st.value == 1, gt.GTE_GetLastError()
    assert gt.GT_StartEcatComm() == 0


def di(ms: int = 2) -> int:
    """Input bit BIT as the application reads it, after ``ms`` of polling."""
    gt.GTE_Wait(ms)
    buf = (c_ubyte * 1)()
    assert gt.GT_EcatIOReadInput(SLAVE, 2, 1, buf) == 0, gt.GTE_GetLastError()
    return buf[0] >> BIT & 1


def field(on: bool) -> None:
    gt.GTE_Slave(SLAVE).set_input_bit(BIT, on)


def test_a_stuck_input_is_released_when_its_time_is_over():
    up()
    faults.inject("io_stuck", slave=SLAVE, bit=BIT, value=1, duration_ms=10)
    assert di() == 1
    assert di(20) == 0  # the field's value again
    assert faults.listing() == []
    s = c_long()
    for _ in range(50):  # polling GT readers (the reader path) reads the same
        gt.GT_GetSts(1, byref(s))
    assert di(0) == 0
    assert not gt.GTE_Slave(SLAVE).held  # nothing laid over the field inputs any more


def test_the_field_set_meanwhile_is_what_the_input_reads_after():
    """Set while held: the input stays held, the release shows the field's last value, also
    when it was set to the held value itself (stuck on, the field switched on meanwhile)."""
    up()
    fid = faults.inject("io_stuck", slave=SLAVE, bit=BIT, value=0)
    field(True)
    assert di() == 0
    faults.clear(fid)
    assert di() == 1
    faults.inject("io_stuck", slave=SLAVE, bit=BIT, value=1, duration_ms=10)
    field(False)
    assert di() == 1
    field(True)  # the same value as the stuck one
    assert di(20) == 1
    field(False)  # released: the field alone from now on
    assert di() == 0


def test_set_input_and_a_raw_write_of_the_field_count_as_the_field():
    up()
    s = gt.GTE_Slave(SLAVE)
    fid = faults.inject("io_stuck", slave=SLAVE, bit=BIT, value=0)
    s.set_input(0x6000, 1, 0xFF)  # the whole input byte, bit 3 with it
    assert di() == 0
    faults.clear(fid)
    assert di() == 1
    fid = faults.inject("io_stuck", slave=SLAVE, bit=BIT, value=1)
    s.field_inputs[0] = 0x00  # a write of the slave's field side that changes the bit
    assert di() == 1
    faults.clear(fid)
    assert di() == 0


def test_two_faults_on_one_input_release_it_to_the_field():
    """The fault added last holds it while both are on; the last one to end releases it to
    the field's value, never to the other fault's."""
    up()
    field(True)
    assert di() == 1
    faults.inject("io_stuck", slave=SLAVE, bit=BIT, value=0, duration_ms=30)
    assert di() == 0
    faults.inject("io_stuck", slave=SLAVE, bit=BIT, value=0, duration_ms=10)
    faults.inject("io_stuck", slave=SLAVE, bit=BIT, value=1, duration_ms=10)
    assert di() == 1
    assert di(15) == 0  # the second and third are over, the first holds it still
    assert di(20) == 1
    assert faults.listing() == []


def test_a_stuck_input_wired_from_an_output_holds_and_lets_go():
    """A terminal's input wired from one of its outputs (a loop-back): the stuck fault holds
    the input over the wire; let go, it reads the wire's value again."""
    up()
    slave = gt.GTE_Slave(SLAVE)
    slave.wire(0, BIT)
    assert gt.GT_EcatIOWriteOutput(SLAVE, 0, 1, bytes([1])) == 0
    assert di(3) == 1  # output bit 0 on: the wire puts it on input bit BIT
    fid = faults.inject("io_stuck", slave=SLAVE, bit=BIT, value=0)
    assert di() == 0
    faults.clear(fid)
    assert di() == 1
