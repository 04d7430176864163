"""A slave cut off mid-run and plugged back (issues 7 and 12 item 4, on the emulated bus).

ETG.1000.4 6.3 process-data watchdog: the slave falls to SAFEOP + error 0x001B; the
drive reacts to the loss of its controlword; the master sees the working counter
drop (GT_IsEcatReady 0 with a reason) and brings the slave back to OP.  The
controller stops the axes of the lost slaves (servo off, alarm bit 1, the plan on the
frozen encoder) and refuses process data that touches them (entries 11, 12, 44, 104);
GT_ClrSts + GT_AxisOn bring an axis back (gtecat.controller.core "Comm loss").
Lockstep clock where times matter: virtual time only, no sleeps.
"""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_short, c_ubyte, c_ushort

from gtecat import gt

from .conftest import bring_up

ALARM, POS_ERROR, SERVO_ON, MOVING = 1 << 1, 1 << 4, 1 << 9, 1 << 10
#: the master takes a short working counter for a loss after 10 ms (gtecat.master.bus)
CONFIRM_MS = 11


def sts(axis: int) -> int:
    s = c_long()
    assert gt.GT_GetSts(axis, byref(s)) == 0
    return s.value


def prf(axis: int) -> float:
    v = c_double()
    assert gt.GT_GetPrfPos(axis, byref(v)) == 0
    return v.value


def enc(axis: int) -> float:
    v = c_double()
    assert gt.GT_GetEncPos(axis, byref(v)) == 0
    return v.value


def move(axis: int, target: int, vel: float = 50.0) -> None:
    prm = gt.TTrapPrm()
    assert gt.GT_PrfTrap(axis) == 0, gt.GTE_GetLastError()
    assert gt.GT_GetTrapPrm(axis, byref(prm)) == 0
    prm.acc, prm.dec, prm.smoothTime = 0.5, 0.5, 0
    assert gt.GT_SetTrapPrm(axis, byref(prm)) == 0
    assert gt.GT_SetPos(axis, target) == 0 and gt.GT_SetVel(axis, vel) == 0
    assert gt.GT_Update(1 << (axis - 1)) == 0, gt.GTE_GetLastError()


def wait_for(pred, ms: int) -> bool:
    for _ in range(ms):
        if pred():
            return True
        gt.GTE_Wait(1)
    return pred()


def ready() -> bool:
    st = c_short()
    return gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1


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


def test_a_mid_move_loss_stops_the_axis_disables_it_and_sets_the_alarm():
    bring_up(clock="lockstep")
    for a in (1, 2):
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
        move(a, 200_000)
    gt.GTE_Wait(100)
    assert sts(2) & (SERVO_ON | MOVING) == SERVO_ON | MOVING
    assert gt.GTE_UnplugSlave(1) == 0  # slaves 1, 2, 3 behind the pulled cable
    gt.GTE_Wait(CONFIRM_MS)
    s = sts(2)
    assert s & ALARM and not s & SERVO_ON and not s & MOVING
    assert s & 0x1F0 == 0  # no following error, limit or stop-input flag (table 6-2)
    frozen = enc(2)
    assert prf(2) == frozen  # the plan took the last encoder value
    gt.GTE_Wait(300)
    assert enc(2) == frozen and prf(2) == frozen  # no runaway
    assert sts(2) & ALARM and not sts(2) & (SERVO_ON | MOVING)
    # axis 1 (slave 0, before the cut) runs on
    assert sts(1) & (SERVO_ON | MOVING) == SERVO_ON | MOVING and not sts(1) & ALARM
    assert "Axis 2: slave 1 (" in gt.GTE_Controller().log.text()


def test_process_data_touching_a_lost_slave_returns_1_naming_it():
    bring_up(clock="lockstep")
    assert gt.GTE_UnplugSlave(2) == 0  # slaves 2 and 3 (IO) cut off
    gt.GTE_Wait(CONFIRM_MS)
    buf = (c_ubyte * 32)(*([0xEE] * 32))

    def refused(rc: int, slave: int) -> None:
        assert rc == 1
        reason = gt.GTE_GetLastError()
        assert f"slave {slave} (" in reason and "does not answer" in reason, reason
        assert bytes(buf) == b"\xee" * 32  # nothing read into the buffer

    refused(gt.GT_GetEcatRawData(34, 2, buf), 2)  # entry 44
    refused(gt.GT_GetEcatRawData(30, 4, buf), 2)  # slave 1's last bytes and slave 2's first
    refused(gt.GT_SetEcatRawData(36, 1, buf), 3)  # entry 104
    refused(gt.GT_EcatIOReadInput(2, 0, 4, buf), 2)  # entry 11
    refused(gt.GT_EcatIOWriteOutput(3, 0, 2, buf), 3)  # entry 12
    refused(gt.GT_EcatIOBitWriteOutput(2, 0, 0, 1), 2)
    # range and input-byte checks come first (7)
    assert gt.GT_EcatIOReadInput(2, 0, 5, buf) == 7
    assert gt.GT_EcatIOWriteOutput(2, 2, 1, buf) == 7
    assert gt.GT_SetEcatRawData(34, 1, buf) == 7
    # the slaves before the cut answer
    assert gt.GT_GetEcatRawData(0, 32, buf) == 0
    assert gt.GT_EcatIOReadInput(1, 6, 2, buf) == 0
    # back: every call works again
    assert gt.GTE_ReplugSlave(2) == 0
    assert wait_for(ready, 1000), gt.GTE_GetLastError()
    assert gt.GT_EcatIOReadInput(2, 0, 4, buf) == 0
    assert gt.GT_EcatIOWriteOutput(3, 0, 2, buf) == 0


def test_recovery_after_replug_needs_clrsts_then_axison_and_the_axis_moves_again():
    bring_up(clock="lockstep")
    assert gt.GT_AxisOn(2) == 0
    move(2, 100_000)
    gt.GTE_Wait(50)
    gt.GTE_UnplugSlave(1)
    gt.GTE_Wait(CONFIRM_MS)
    # while it is gone: nothing clears bit 1, nothing enables or moves the axis
    assert gt.GT_AxisOn(2) == 1
    assert "slave 1 (" in gt.GTE_GetLastError() and "does not answer" in gt.GTE_GetLastError()
    assert gt.GT_ClrSts(2) == 0 and sts(2) & ALARM
    assert gt.GT_Reset() == 0 and sts(2) & ALARM
    assert gt.GT_PrfTrap(2) == 0 and gt.GT_SetPos(2, 0) == 0 and gt.GT_SetVel(2, 10) == 0
    assert gt.GT_Update(2) == 1  # servo off, alarm set
    gt.GTE_Wait(300)  # the drive's watchdog runs out meanwhile
    assert gt.GTE_ReplugSlave(1) == 0
    assert wait_for(ready, 1000), gt.GTE_GetLastError()
    assert sts(2) & ALARM  # latched until GT_ClrSts
    assert gt.GT_AxisOn(2) == 1 and "GT_ClrSts" in gt.GTE_GetLastError()
    assert gt.GT_ClrSts(2) == 0
    assert not sts(2) & ALARM, gt.GTE_GetLastError()
    assert gt.GT_AxisOn(2) == 0, gt.GTE_GetLastError()
    start = round(enc(2))
    move(2, start + 20_000)
    assert wait_for(lambda: not sts(2) & MOVING, 5000)
    gt.GTE_Wait(20)
    assert abs(enc(2) - (start + 20_000)) <= 2
    assert sts(2) & SERVO_ON and not sts(2) & ALARM
