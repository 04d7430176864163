"""The older homing calls of a GTS card, as the vendor's demos call them: GT_ClrSts,
GT_HomeInit, GT_AxisOn, GT_Index (axis 1 homes on Home + Index), GT_Home per axis, then
GT_HomeSts polled until it gives 1.

Every expected position comes from the machine description below: a card latches the
home and index edges exactly; the home edge is where the switch is reached."""

from __future__ import annotations

from ctypes import byref, c_double, c_ushort

from gtecat import gt
from gtecat.drives.machine import AxisMachine, MachineDescription

HOME1, HOME2, IDX0, CPR = 10000, -4000, 1234, 5000


def open_card() -> None:
    machine = MachineDescription(
        {
            1: AxisMachine(
                counts_per_rev=CPR,
                index_offset=IDX0,
                negative_limit=-30000,
                positive_limit=30000,
                home_switch=((HOME1, HOME1 + 2000),),
            ),
            2: AxisMachine(home_switch=((HOME2 - 1000, HOME2),)),
        }
    )
    assert gt.GT_Open(card="gts:4", machine=machine, clock="lockstep", log="") == 0
    assert gt.GT_ClrSts(1, 4) == 0


def prf(axis: int) -> float:
    p = c_double()
    assert gt.GT_GetPrfPos(axis, byref(p)) == 0
    return p.value


def home_sts(axis: int) -> tuple[int, int]:
    sts = c_ushort(7)
    rc = gt.GT_HomeSts(axis, byref(sts))
    return rc, sts.value


def wait_done(*axes: int, ms: int = 5000) -> None:
    for _ in range(ms // 5):
        if all(home_sts(a) == (0, 1) for a in axes):
            return
        gt.GTE_Wait(5)
    raise AssertionError(f"homing never ended: {[home_sts(a) for a in axes]}")


def test_the_vendor_demo_homes_axis_1_on_home_and_index_and_axis_2_on_home():
    open_card()
    assert gt.GT_HomeInit() == 0
    assert gt.GT_AxisOn(1) == 0 and gt.GT_AxisOn(2) == 0
    assert home_sts(1) == (0, 0)  # nothing ran yet
    assert gt.GT_Index(1, 20000, 2000) == 0  # arms axis 1's index stage; nothing moves
    assert prf(1) == 0.0
    assert gt.GT_Home(1, 200000, 50, 0.5, 2000) == 0, gt.GTE_GetLastError()
    assert gt.GT_Home(2, -200000, 50, 0.5, 3000) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(20)
    assert home_sts(1) == (0, 0) and home_sts(2) == (0, 0)  # running
    wait_done(1, 2)
    first_index_beyond_home = IDX0 + CPR * 2  # 11234: the first pulse past 10000
    assert prf(1) == first_index_beyond_home + 2000  # the Index call's offset
    assert prf(2) == HOME2 + 3000  # reached from above: the switch's upper edge
    st = gt.THomeStatus()
    assert gt.GT_GetHomeStatus(1, byref(st)) == 0 and st.capturePos == first_index_beyond_home


def test_home_stop_stands_on_the_home_and_gtn_twins_work():
    open_card()
    assert gt.GTN_AxisOn(1, 1) == 0
    assert gt.GTN_HomeInit(1) == 0
    assert gt.GTN_HomeStop(1, 1, 50000, 20.0, 1.0) == 0, gt.GTE_GetLastError()
    sts = c_ushort()
    for _ in range(400):
        assert gt.GTN_HomeSts(1, 1, byref(sts)) == 0
        if sts.value == 1:
            break
        gt.GTE_Wait(5)
    assert sts.value == 1 and prf(1) == HOME1
    # GT_HomeInit forgets an armed index: the next GT_Home is a plain home search
    assert gt.GT_Index(1, 20000, 500) == 0 and gt.GT_HomeInit() == 0
    assert gt.GT_Home(1, 50000, 20.0, 1.0, 0) == 0, gt.GTE_GetLastError()
    wait_done(1)
    assert prf(1) == HOME1  # on the switch: off it backwards, then the same edge again


def test_bad_arguments_and_a_failed_homing():
    open_card()
    assert gt.GT_AxisOn(1) == 0
    assert gt.GT_Home(1, 20000, 0.0, 1.0, 0) == 7  # vel must be > 0
    assert gt.GT_Home(1, 0, 10.0, 1.0, 0) == 7  # the axis stands at 0: no direction
    assert gt.GT_Home(9, 20000, 10.0, 1.0, 0) == 7
    assert gt.GT_Index(9, 100, 0) == 7
    assert gt.GT_HomeSts(1, None) == 7
    ctl = gt.GTE_Controller()
    # no GT_HomeInit: it homes anyway, with a line in the master log
    assert gt.GT_Home(1, -20000, 40.0, 2.0, 0) == 0  # the home is above: never found
    assert any("without GT_HomeInit" in line for line in ctl.log.lines)
    for _ in range(300):
        rc, sts = home_sts(1)
        if rc:
            break
        gt.GTE_Wait(5)
    assert (rc, sts) == (1, 0)
    assert "homing of axis 1 failed" in gt.GTE_GetLastError()
