"""GT bus calls through ``from gtecat import gt``, written the way ctypes code for the DLL is.

Manual chapter 5: 5.2.2.1 (communication), 5.2.2.4 (PDO raw data, figure 5-2 offsets),
5.2.2.5 (EtherCAT IO, figure 5-4 offsets), examples 5-1, 5-4, 5-5; chapter 13 entries
11, 12, 13, 14, 33, 44, 45, 56, 79, 80, 104, 129, 136; table 3-1 return codes.
"""

from __future__ import annotations

import ctypes
import re
from ctypes import byref, c_short, c_ubyte, c_uint32, c_ulong, c_ushort

import pytest

from gtecat import gt
from tests.conftest import EXAMPLES

from .conftest import bring_up


def test_example_5_5_c_initialisation_sequence():
    """Example 5-5: GT_Open, GT_InitEcatComm, wait for GT_IsEcatReady, start, reset."""
    assert gt.GT_Open(gt.CHANNEL_PCI_ECATCH, eni=str(EXAMPLES / "manual_fig5_2.eni"), log="") == 0
    assert gt.GT_InitEcatComm() == 0
    status = c_short(0)
    polls = 0
    while True:
        rtn = gt.GT_IsEcatReady(byref(status))
        polls += 1
        if not (status.value != 1 or rtn != 0):
            break
    assert polls > 1  # OP comes a few cycles after init, as on the real master
    assert gt.GT_StartEcatComm() == 0
    assert gt.GT_Reset() == 0
    clock = c_ulong()
    assert gt.GT_GetClock(byref(clock)) == 0
    assert clock.value == 0


def test_example_5_1_status_before_and_after():
    assert gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), log="", clock="lockstep") == 0
    st = c_short(7)
    # before any GT_InitEcatComm: 1 with the reason, so a polling loop ends
    assert gt.GT_IsEcatReady(byref(st)) == 1 and st.value == 0
    assert "call GT_InitEcatComm" in gt.GTE_GetLastError()
    assert gt.GT_InitEcatComm() == 0
    assert gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 0
    assert gt.GT_StartEcatComm() == 1  # not yet in OP: motion control cannot start
    assert "GT_IsEcatReady" in gt.GTE_GetLastError()
    gt.GTE_Wait(20)
    assert gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1


def test_slave_and_axis_counts():
    bring_up()
    n, motion, io = c_short(), c_short(), c_short()
    assert gt.GT_GetEcatSlaves(byref(n)) == 0 and n.value == 4
    assert gt.GT_GetEcatSlaves(byref(motion), byref(io)) == 0
    assert (motion.value, io.value) == (2, 2)
    axes = c_short()
    assert gt.GT_GetMcEcatAxisNum(byref(axes)) == 0 and axes.value == 2
    length = c_short()
    assert gt.GT_GetEcatPdoLength(byref(length)) == 0 and length.value == 40


def test_raw_write_reaches_the_output_and_the_wired_input_comes_back():
    """5.2.2.4 (3): slave 2 outputs at 32, inputs at 34."""
    bring_up()
    io = gt.GTE_Slave(2)
    for bit in range(16):
        io.wire(bit, bit)
    w = c_ushort(0xA55A)
    assert gt.GT_SetEcatRawData(32, 2, byref(w)) == 0
    assert gt.GT_EcatIOSynch() == 0
    assert io.get_output(0x7000, 1) == 0x5A and io.get_output(0x7000, 2) == 0xA5
    gt.GTE_Wait(2)
    back = c_ushort()
    assert gt.GT_GetEcatRawData(34, 2, byref(back)) == 0
    assert back.value == 0xA55A
    # slave 3 (region 36) is untouched
    other = (c_ubyte * 4)()
    assert gt.GT_GetEcatRawData(36, 4, other) == 0
    assert bytes(other) == b"\0\0\0\0"


def test_raw_offsets_of_the_drives_match_figure_5_2():
    """Slave 0: 6040 at 0, 6041 at 6; slave 1: 6040 at 16, 6041 at 22."""
    bring_up()
    gt.GTE_Wait(2)
    for slave, sw_off in ((0, 6), (1, 22)):
        buf = (c_ubyte * 2)()
        assert gt.GT_GetEcatRawData(sw_off, 2, buf) == 0
        assert bytes(buf) == bytes(gt.GTE_Slave(slave).tx[0:2])
    cw = c_ushort(0x0006)
    assert gt.GT_SetEcatRawData(16, 2, byref(cw)) == 0
    gt.GTE_Wait(2)
    assert bytes(gt.GTE_Slave(1).rx[0:2]) == b"\x06\x00"


@pytest.mark.parametrize(
    "offset, size",
    [(39, 2), (40, 1), (0, 41), (-1, 2)],
)
def test_raw_out_of_range_returns_7_and_changes_nothing(offset, size):
    bring_up()
    before = (c_ubyte * 40)()
    gt.GT_GetEcatRawData(0, 40, before)
    buf = (c_ubyte * 64)(*([0xFF] * 64))
    assert gt.GT_SetEcatRawData(offset, size, buf) == 7
    reason = gt.GTE_GetLastError()
    assert "outside" in reason or "out of range 0..65535" in reason, reason
    assert gt.GT_GetEcatRawData(offset, size, buf) == 7
    after = (c_ubyte * 40)()
    gt.GT_GetEcatRawData(0, 40, after)
    assert bytes(after[:32]) == bytes(before[:32])


def test_raw_write_touching_inputs_is_refused():
    bring_up()
    buf = (c_ubyte * 4)(1, 2, 3, 4)
    assert gt.GT_SetEcatRawData(32, 4, buf) == 7  # bytes 34, 35 are slave 2's inputs
    assert "input byte" in gt.GTE_GetLastError()
    gt.GTE_Wait(2)
    assert gt.GTE_Slave(2).get_output(0x7000, 1) == 0  # nothing of the write landed


def test_example_5_4_ethercat_io_on_the_coupler():
    """Example 5-4 / 5.2.2.5 with the figure 5-4 coupler (slave 0)."""
    bring_up("manual_fig5_4.eni")
    coupler = gt.GTE_Slave(0)
    coupler.set_input(0x6000, 1, 0xBEEF)
    for ch, v in enumerate((100, -200, 300, -400), start=1):
        coupler.set_input(0x6020, ch, v)
    gt.GTE_Wait(2)
    w_input = c_ushort()
    assert gt.GT_EcatIOReadInput(0, 14, 2, byref(w_input)) == 0
    assert w_input.value == 0xBEEF
    ai1, ai2 = ctypes.c_short(), ctypes.c_short()
    assert gt.GT_EcatIOReadInput(0, 16, 2, byref(ai1)) == 0
    assert gt.GT_EcatIOReadInput(0, 18, 2, byref(ai2)) == 0
    assert (ai1.value, ai2.value) == (100, -200)
    ai34 = (ctypes.c_short * 2)()
    assert gt.GT_EcatIOReadInput(0, 20, 4, ai34) == 0
    assert list(ai34) == [300, -400]
    w_out = c_ushort(0x1234)
    assert gt.GT_EcatIOWriteOutput(0, 2, 2, byref(w_out)) == 0
    ao = (ctypes.c_short * 4)(1, 2, 3, 4)
    assert gt.GT_EcatIOWriteOutput(0, 4, 8, ao) == 0
    gt.GTE_Wait(2)
    assert coupler.get_output(0x7010, 1) == 0x1234
    assert [coupler.get_output(0x7030, k) for k in range(1, 5)] == [1, 2, 3, 4]
    # the GTN twin with the EtherCAT core first, as 5.2.2.5 writes it
    assert gt.GTN_EcatIOReadInput(1, 0, 14, 2, byref(w_input)) == 0
    assert gt.GTN_EcatIOReadInput(3, 0, 14, 2, byref(w_input)) == 7  # no core 3
    # core 2 is the card's pulse core (gtecat.controller.cards): no EtherCAT there
    assert gt.GTN_EcatIOReadInput(2, 0, 14, 2, byref(w_input)) == 1
    # the manual's 5.2.2.5 text spells it with the core first: GT_EcatIOReadInput(1, 0, 14, 2, ...)
    assert gt.GT_EcatIOReadInput(1, 0, 14, 2, byref(w_input)) == 0 and w_input.value == 0xBEEF
    assert gt.GT_EcatIOWriteOutput(1, 0, 2, 2, byref(w_out)) == 0
    assert gt.GT_EcatIOReadInput(2, 0, 14, 2, byref(w_input)) == 7  # no core 2
    # outside the slave's 24-byte region, or writing its inputs: 7
    assert gt.GT_EcatIOReadInput(0, 23, 2, byref(w_input)) == 7
    assert gt.GT_EcatIOWriteOutput(0, 12, 2, byref(w_out)) == 7
    assert gt.GT_EcatIOReadInput(1, 0, 2, byref(w_input)) == 7


def test_bit_write_output():
    bring_up()
    assert gt.GT_EcatIOBitWriteOutput(3, 1, 7, 1) == 0
    assert gt.GT_EcatIOBitWriteOutput(3, 1, 8, 1) == 7
    gt.GTE_Wait(2)
    assert gt.GTE_Slave(3).get_output(0x7000, 2) == 0x80


def test_return_codes_of_init():
    """Entry 79: -9 no ENI, -8 slaves differ from the ENI."""
    assert gt.GT_Open(eni="/nonexistent/Gecat.eni", log="") == 0
    assert gt.GT_InitEcatComm() == -9
    assert "Gecat.eni" in gt.GTE_GetLastError()
    gt.GT_Close()
    assert (
        gt.GT_Open(
            eni=str(EXAMPLES / "manual_fig5_2.eni"), bus=str(EXAMPLES / "manual_fig5_4.eni"), log=""
        )
        == 0
    )
    assert gt.GT_InitEcatComm() == -8
    assert "slave 0" in gt.GTE_GetLastError()


def test_open_close_and_not_open():
    n = c_short()
    assert gt.GT_GetEcatSlaves(byref(n)) == -1
    assert "GT_Open" in gt.GTE_GetLastError()
    assert gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), log="") == 0
    assert gt.GT_Open() == -6
    assert gt.GT_Close() == 0


def test_raw_data_before_init_returns_1():
    assert gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), log="") == 0
    buf = (c_ubyte * 2)()
    assert gt.GT_GetEcatRawData(0, 2, buf) == 1
    assert "GT_InitEcatComm" in gt.GTE_GetLastError()


def test_clock_counts_controller_milliseconds():
    bring_up(clock="lockstep")
    gt.GT_Reset()
    gt.GTE_Wait(25)
    ms, loops = c_ulong(), c_ulong()
    assert gt.GT_GetClock(byref(ms), byref(loops)) == 0
    assert ms.value == 25


def test_version_and_slave_info():
    bring_up()
    ver = ctypes.create_string_buffer(64)
    assert gt.GT_GetVersion(ver) == 0 and ver.value == b"010 261201 010 261201"  # table 11-3
    info = gt.TSlaveInfo()
    assert gt.GT_GetEcatSlaveInfo(2, byref(info)) == 0
    assert (info.pdoOffset, info.outputBytes, info.inputBytes, info.state) == (32, 2, 2, 8)
    assert gt.GT_GetEcatSlaveInfo(1, byref(info)) == 0
    assert (info.axisCount, info.firstAxis) == (1, 2)
    assert gt.GT_GetEcatSlaveInfo(9, byref(info)) == 7


def test_sdo_upload_download_and_abort_code():
    bring_up()
    data = (c_ubyte * 4)()
    size, abort = c_uint32(), c_uint32()
    assert gt.GT_EcatSDOUpload(0, 0x1018, 1, data, 4, byref(size), byref(abort)) == 0
    assert size.value == 4 and abort.value == 0
    assert gt.GT_EcatSDOUpload(0, 0x5FFF, 0, data, 4, byref(size), byref(abort)) == 1
    assert abort.value == 0x06020000
    ro = (c_ubyte * 2)(1, 0)
    assert gt.GT_EcatSDODownload(0, 0x6041, 0, ro, 2, byref(abort)) == 1
    assert abort.value == 0x06010002


def test_master_log_reads_like_the_real_one():
    bring_up()
    lines = gt.GTE_Controller().log.lines
    text = "\n".join(lines)
    assert "Scanning bus" in text
    assert "Slave states: PREOP" in text
    assert "All slaves are in OP mode" in text


def _stamp(line: str) -> int:
    m = re.match(r"\[\s*(\d+) ms\] EtherCAT: ", line)
    assert m, line
    return int(m.group(1))


def test_master_log_time_is_what_gt_get_clock_reads():
    """The master log is the controller's, GT_GetClock reads the controller's clock and
    GT_Reset resets the controller (chapter 13): the log's time counts from GT_Reset as
    GT_GetClock does (example 5-5's GT_Reset comes after the bus is up, some ms after power-on),
    and GT_Reset says in the log that its time goes back to 0."""
    from gtecat import faults

    assert gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), log="") == 0
    assert gt.GT_InitEcatComm() == 0
    status = c_short(0)
    while not (gt.GT_IsEcatReady(byref(status)) == 0 and status.value == 1):
        pass
    assert gt.GT_StartEcatComm() == 0
    clock = c_ulong()
    assert gt.GT_GetClock(byref(clock)) == 0
    before = clock.value
    assert before > 0  # (the bring-up took controller time)
    assert gt.GT_Reset() == 0
    log = gt.GTE_Controller().log
    assert _stamp(log.lines[-1]) == before
    assert f"clock counts from 0 again (it read {before} ms)" in log.lines[-1]
    faults.inject("drive_fault", axis=1, at_ms=200)
    gt.GTE_Wait(150)
    assert gt.GT_GetClock(byref(clock)) == 0
    assert gt.GT_Reset() == 0  # (from a time that is not a whole cycle's start too)
    assert _stamp(log.lines[-1]) == clock.value
    gt.GTE_Wait(300)
    started = [line for line in log.lines if "Fault 1 started" in line]
    assert [_stamp(line) for line in started] == [200]  # (at_ms: GT_GetClock's time too)
    assert gt.GT_GetClock(byref(clock)) == 0
    assert clock.value == 300
    gt.GT_Close()


def test_pointers_of_the_other_kind_of_number_are_7_with_a_reason():
    """``long *`` memory where the prototype has ``double *`` (and a ``c_double`` for a
    ``long *``) is refused: C would not compile it, and the value would be rounded."""
    bring_up()
    gt.GTE_Controller().axis(1).prf_pos = 12.6
    as_long, arr = ctypes.c_long(-5), (ctypes.c_long * 2)()
    assert gt.GT_GetPrfPos(1, byref(as_long)) == 7  # the fast path's shape
    assert "c_long" in gt.GTE_GetLastError() and "double" in gt.GTE_GetLastError()
    assert gt.GT_GetPrfPos(1, arr, 1) == 7
    assert gt.GT_GetSts(1, byref(ctypes.c_double())) == 7
    assert gt.GT_GetPrfPos(1, byref(ctypes.c_float())) == 7
    assert as_long.value == -5 and list(arr) == [0, 0]
    pos = ctypes.c_double()
    assert gt.GT_GetPrfPos(1, byref(pos)) == 0
    sts = ctypes.c_int32()  # the vendor's 32-bit long: another width of integer is fine
    assert gt.GT_GetSts(1, byref(sts)) == 0


def test_emulator_only_helpers_refuse_other_backends_with_a_reason():
    bring_up()
    ctl = gt.GTE_Controller()
    real, ctl.backend = ctl.backend, object()  # stands in for a non-emulated backend
    try:
        pos = ctypes.c_double()
        assert gt.GTE_GetMachinePos(1, byref(pos)) == 1
        assert "emulated" in gt.GTE_GetLastError()
        assert gt.GTE_UnplugSlave(1) == 1 and "emulated" in gt.GTE_GetLastError()
    finally:
        ctl.backend = real


def test_init_again_finds_the_load_where_the_last_bus_left_it():
    """Example 5-5's sequence run twice in one controller (an application restarting on a
    running controller, or a second client's bring-up): the second GT_InitEcatComm does not
    move the machine back to its power-on position; the encoder reads where the axis went."""
    from ctypes import c_double

    bring_up()
    assert gt.GT_ClrSts(1, 1) == 0 and gt.GT_AxisOn(1) == 0
    assert gt.GT_PrfTrap(1) == 0
    prm = gt.TTrapPrm(acc=1, dec=1, velStart=0, smoothTime=0)
    assert gt.GT_SetTrapPrm(1, byref(prm)) == 0
    assert gt.GT_SetPos(1, 30000) == 0 and gt.GT_SetVel(1, 50) == 0
    assert gt.GT_Update(1) == 0
    assert gt.GTE_Wait(1500) == 0
    enc = c_double()
    assert gt.GT_GetEncPos(1, byref(enc)) == 0 and abs(enc.value - 30000) < 2, enc.value
    assert gt.GT_TerminateEcatComm() == 0
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    ready = c_short()
    for _ in range(1000):
        if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
            break
        assert gt.GTE_Wait(1) == 0
    assert ready.value == 1
    assert gt.GT_GetEncPos(1, byref(enc)) == 0 and abs(enc.value - 30000) < 2, enc.value
