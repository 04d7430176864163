"""A slave cut off mid-run and plugged back (issue 7's check, on the emulated bus).

ETG.1000.4 6.3 process-data watchdog: the slave falls to SAFEOP + error 0x001B; the
drive reacts to the loss of its controlword; the master sees the working counter
drop (GT_IsEcatReady 0 with a reason) and brings the slave back to OP.
"""

from __future__ import annotations

from ctypes import byref, c_short, c_ushort

from gtecat import gt

from .conftest import bring_up


def test_unplug_and_replug_a_slave():
    bring_up()
    io = gt.GTE_Slave(3)
    io.wire(0, 0)
    assert gt.GT_AxisOn(1) == 0
    st = c_short()
    assert gt.GTE_UnplugSlave(3) == 0
    gt.GTE_Wait(5)
    assert gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 0
    gt.GTE_Wait(150)
    assert io.al_state.name == "SAFEOP" and int(io.al_status_code) == 0x1B
    log = gt.GTE_Controller().log.text()
    assert "Working counter changed" in log
    assert gt.GTE_ReplugSlave(3) == 0
    gt.GTE_Wait(300)
    assert gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1, gt.GTE_GetLastError()
    assert "Slave 3: back in OP" in gt.GTE_Controller().log.text()
    # process data flows again through the wire
    assert gt.GT_SetEcatRawData(36, 1, byref(c_ushort(1))) == 0
    gt.GTE_Wait(3)
    back = c_ushort()
    gt.GT_GetEcatRawData(38, 1, byref(back))
    assert back.value & 1


def test_a_cut_off_drive_loses_its_controlword():
    bring_up()
    assert gt.GT_AxisOn(2) == 0
    ch = gt.GTE_Slave(1).channel(0)
    assert ch.state.name == "OPERATION_ENABLED"
    gt.GTE_UnplugSlave(1)  # slaves 1, 2, 3 behind the pulled cable
    gt.GTE_Wait(200)
    assert ch.state.name != "OPERATION_ENABLED"
    gt.GTE_ReplugSlave(1)
    gt.GTE_Wait(400)
    st = c_short()
    assert gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1
    assert gt.GTE_UnplugSlave(9) == 7
