"""The Ex forms of the buffered lines and arcs with double coordinates, as a look-ahead
application pushes them (``GT_LnXYEx`` ... ``GT_CrdDataEx(crd, NULL, fifo)`` to flush), and
``GT_BufGear``: a rotary axis carried along with the next segment of the path."""

from __future__ import annotations

from ctypes import byref, c_double, c_int32, c_long, c_short

from gtecat import gt


def card() -> None:
    assert gt.GT_Open(card="gts:4", clock="lockstep", log="") == 0
    for a in (1, 2, 3, 4):
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
    prm = gt.TCrdPrm()
    prm.dimension, prm.synVelMax, prm.synAccMax = 3, 100.0, 2.0
    for c, a in enumerate((1, 2, 3), 1):
        prm.profile[a - 1] = c
    assert gt.GT_SetCrdPrm(1, byref(prm)) == 0, gt.GTE_GetLastError()


def prf(axis: int) -> float:
    p = c_double()
    assert gt.GT_GetPrfPos(axis, byref(p)) == 0
    return p.value


def running() -> bool:
    run, seg = c_short(), c_int32()
    assert gt.GT_CrdStatus(1, byref(run), byref(seg)) == 0
    return bool(run.value)


def finish() -> None:
    for _ in range(20000):
        if not running():
            return
        gt.GTE_Wait(1)
    raise AssertionError("the path never ended")


def test_ex_lines_and_arcs_follow_fractional_points():
    card()
    assert gt.GT_LnXYEx(1, 1000.5, 0.25, 20.0, 1.0, 7, 0) == 0, gt.GTE_GetLastError()
    assert gt.GT_ArcXYCEx(1, 1000.5, 2000.25, 0.0, 1000.0, 1, 20.0, 1.0, 8, 0) == 0
    assert gt.GT_ArcXYREx(1, 2000.5, 3000.25, 1000.0, 0, 20.0, 1.0, 9, 1) == 0
    assert gt.GT_LnXYZEx(1, 2000.5, 3000.25, 500.0, 20.0, 1.0, 10, 0) == 0
    assert gt.GT_ArcYZREx(1, 3000.25, 1000.0, 500.0, 0, 20.0, 1.0, 11, 0) == 0
    assert gt.GT_ArcYZCEx(1, 3000.25, 500.0, 0.0, -250.0, 1, 20.0, 1.0, 12, 0) == 0
    assert gt.GT_ArcZXREx(1, 1000.0, 2500.5, 707.2, 0, 20.0, 1.0, 13, 0) == 0
    assert gt.GT_ArcZXCEx(1, 1000.0, 2500.5, 0.0, 100.0, 0, 20.0, 1.0, 14, 0) == 0  # full circle
    assert gt.GT_LnXYG0Ex(1, 0.0, 0.0, 50.0, 1.0, 15, 0) == 0
    assert gt.GT_LnXYZG0Ex(1, 10.0, 10.0, 10.0, 50.0, 1.0, 16, 0) == 0
    assert gt.GT_CrdDataEx(1, None, 0) == 0  # the flush: nothing is held back
    assert gt.GT_CrdStart(1, 0) == 0
    finish()
    assert (prf(1), prf(2), prf(3)) == (10.0, 10.0, 10.0)
    assert gt.GT_LnXYEx(1, 1.0, 1.0, 20.0, 1.0, 1, 2) == 7  # override2 is 0 or 1
    assert gt.GT_LnXYEx(1, float("nan"), 1.0, 20.0, 1.0, 1, 0) == 7
    assert gt.GT_CrdDataEx(1, byref(c_long()), 0) == 1  # a TCrdData segment: not emulated


def test_a_four_axis_ex_line_and_its_g0():
    assert gt.GT_Open(card="gts:4", clock="lockstep", log="") == 0
    prm = gt.TCrdPrm()
    prm.dimension, prm.synVelMax, prm.synAccMax = 4, 100.0, 2.0
    for a in (1, 2, 3, 4):
        assert gt.GT_AxisOn(a) == 0
        prm.profile[a - 1] = a
    assert gt.GT_SetCrdPrm(1, byref(prm)) == 0
    assert gt.GT_LnXYZAEx(1, 100.5, 200.0, 300.0, 400.0, 50.0, 2.0, 1, 0) == 0
    assert gt.GT_LnXYZAG0Ex(1, 0.0, 0.0, 0.0, 50.0, 50.0, 2.0, 2, 0) == 0
    assert gt.GT_CrdStart(1, 0) == 0
    finish()
    assert (prf(1), prf(4)) == (0.0, 50.0)


def test_buf_gear_carries_an_axis_along_with_the_next_segment():
    card()
    assert gt.GT_LnXY(1, 1000, 0, 20.0, 1.0) == 0
    assert gt.GT_BufGear(1, 4, 3600) == 0  # axis 4 turns 3600 pulses with the next line
    assert gt.GT_LnXY(1, 3000, 0, 20.0, 1.0) == 0
    assert gt.GT_BufGearEx(1, 4, -600.5) == 0
    assert gt.GT_LnXY(1, 3000, 1000, 20.0, 1.0) == 0
    assert gt.GT_BufGear(1, 1, 100) == 7  # an axis of the system
    assert gt.GT_CrdStart(1, 0) == 0
    mode = c_long()
    seen = []
    while running():
        gt.GTE_Wait(5)
        x = prf(1)
        if 1000 < x < 3000:
            seen.append((x, prf(4)))
            assert gt.GT_GetPrfMode(4, byref(mode)) == 0 and mode.value == 3
    assert seen and all(abs(g - (x - 1000) * 1.8) < 1e-6 for x, g in seen)
    assert prf(4) == 3600 - 600.5
    assert gt.GT_GetPrfMode(4, byref(mode)) == 0 and mode.value == 0  # Trap again
    assert gt.GT_SetPos(4, 0) == 0 and gt.GT_SetVel(4, 50.0) == 0 and gt.GT_Update(1 << 3) == 0
