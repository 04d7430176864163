"""The GTN look-ahead in user units, as the vendor's GSN sample sets it up:
GTN_SetupLookAheadCrd, the ...ModeLa settings, GTN_InitLookAheadEx, then Ex lines in mm
(speed in mm/s, acceleration in mm/s²), GTN_CrdDataEx(NULL) and GTN_CrdStart."""

from __future__ import annotations

from ctypes import byref, c_double, c_int, c_int32, c_short

from gtecat import gt

SCALE = 1000.0  # pulses per mm


def card(dimension: int = 2, opened: bool = False) -> None:
    if not opened:
        assert gt.GT_Open(card="gts:4", clock="lockstep", log="") == 0
    for a in range(1, 5):
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
    prm = gt.TCrdPrm()
    prm.dimension, prm.synVelMax, prm.synAccMax = dimension, 500.0, 10.0
    for c in range(1, dimension + 1):
        prm.profile[c - 1] = c
    assert gt.GTN_SetCrdPrm(1, 1, byref(prm)) == 0, gt.GTE_GetLastError()


def para(**kw) -> gt.TLookAheadParameter:
    p = gt.TLookAheadParameter()
    p.lookAheadNum, p.time, p.radiusRatio = 200, 1.0, 0.001
    for i in range(8):
        p.vMax[i], p.aMax[i], p.DVMax[i] = 100.0, 5000.0, 50.0  # mm/s, mm/s², mm/s
        p.scale[i], p.axisRelation[i] = SCALE, i + 1
    for k, v in kw.items():
        setattr(p, k, v)
    return p


def prf(axis: int) -> float:
    p = c_double()
    assert gt.GT_GetPrfPos(axis, byref(p)) == 0
    return p.value


def run_path(ms: int = 5000) -> float:
    """Run FIFO 0 of system 1 to its end; the fastest path speed seen (pulse/ms)."""
    assert gt.GTN_CrdStart(1, 1, 0) == 0, gt.GTE_GetLastError()
    run, seg, vel, top = c_short(), c_int32(), c_double(), 0.0
    for _ in range(ms // 5):
        gt.GTE_Wait(5)
        assert gt.GTN_GetCrdVel(1, 1, byref(vel)) == 0
        top = max(top, vel.value)
        assert gt.GTN_CrdStatus(1, 1, byref(run), byref(seg), 0) == 0
        if not run.value:
            return top
    raise AssertionError("the path never ended")


def test_the_gsn_sample_runs_its_path_in_millimetres():
    card()
    ctl = gt.GTE_Controller()
    assert gt.GTN_SetupLookAheadCrd(1, 1, gt.NORMAL_THREE_AXIS) == 0, gt.GTE_GetLastError()
    limit_mode = (c_int * 8)(1, 1, 0, 0, 0, 0, 0, 0)
    assert gt.GTN_SetAxisFollowModeLa(1, 1, (c_int * 8)()) == 0, gt.GTE_GetLastError()
    assert gt.GTN_SetAxisLimitModeLa(1, 1, limit_mode) == 0, gt.GTE_GetLastError()
    assert gt.GTN_SetAxisVelValidModeLa(1, 1, 0xF) == 0
    assert gt.GTN_SetVelModeLa(1, 1, gt.S_CURVE) == 0
    assert gt.GTN_SetVelSmoothModeLa(1, 1, 1) == 0
    assert gt.GTN_SetVelDefineModeLa(1, 1, gt.NORMAL_DEF_VEL) == 0
    assert gt.GTN_SetAccDefineModeLa(1, 1, gt.LONG_AXIS_ACC) == 0
    assert gt.GTN_SetWorkLimitModeLa(1, 1, gt.WORK_LIMIT_INVALID) == 0
    assert gt.GTN_SetAxisVelValidCompModeLa(1, 1, 0, (c_int * 8)()) == 0
    assert gt.GTN_SetFollowAxisProcessModeLa(1, 1, 0) == 0
    assert any("GT_SetVelModeLa" in line and "trapezoidal" in line for line in ctl.log.lines)
    assert gt.GTN_InitLookAheadEx(1, 1, byref(para()), 0, 0) == 0, gt.GTE_GetLastError()
    assert gt.GTN_LnXYEx(1, 1, 20, 10, 50, 1000, 0, 0) == 0, gt.GTE_GetLastError()
    assert gt.GTN_ArcXYCEx(1, 1, 30, 20, 0, 10, 1, 50, 1000, 1, 0, 0) == 0  # a quarter circle
    assert gt.GTN_CrdDataEx(1, 1, None, 0) == 0
    top = run_path()
    assert (prf(1), prf(2)) == (30 * SCALE, 20 * SCALE)
    assert abs(top - 50 * SCALE / 1000) < 1e-6  # 50 mm/s = 50 pulse/ms at 1000 pulse/mm


def test_vmax_holds_the_path_speed_and_init_look_ahead_goes_back_to_pulses():
    card()
    assert gt.GT_InitLookAheadEx(1, byref(para(lookAheadNum=5)), 0) == 0, gt.GTE_GetLastError()
    p = para()
    p.vMax[1] = 20.0  # mm/s on Y: the path is held to 20 pulse/ms
    assert gt.GT_InitLookAheadEx(1, byref(p), 0, 0, None) == 0
    assert gt.GT_LnXYEx(1, 5, 5, 50, 1000, 0, 0) == 0
    assert gt.GT_CrdDataEx(1, None) == 0
    assert abs(run_path() - 20.0) < 1e-6
    assert (prf(1), prf(2)) == (5000.0, 5000.0)
    assert gt.GT_InitLookAhead(1, 0, 5.0, 1.0, 10, None) == 0  # the pulse look-ahead again
    assert gt.GT_LnXYEx(1, 100, 200, 10, 1, 0, 0) == 0
    run_path()
    assert (prf(1), prf(2)) == (100.0, 200.0)


def test_what_is_refused_and_why():
    assert gt.GT_Open(card="gts:4", clock="lockstep", log="") == 0
    assert gt.GT_InitLookAheadEx(1, byref(para()), 0) == 1  # no GT_SetCrdPrm yet
    assert "GT_SetCrdPrm" in gt.GTE_GetLastError()
    card(opened=True)
    assert gt.GT_SetupLookAheadCrd(1, gt.ROBOT) == 1
    assert "not emulated" in gt.GTE_GetLastError()
    assert gt.GT_SetupLookAheadCrd(1, 9) == 7
    assert gt.GT_SetupLookAheadCrd(3, 0) == 7
    assert gt.GT_SetVelModeLa(1, 4) == 7
    assert gt.GT_SetAxisLimitModeLa(1, (c_int * 8)(0, -1)) == 7
    assert gt.GT_SetAxisLimitModeLa(1, None) == 7
    assert gt.GT_InitLookAheadEx(1, None, 0) == 7
    assert gt.GT_InitLookAheadEx(1, byref(para(time=0.0)), 0) == 7
    assert gt.GT_InitLookAheadEx(1, byref(para(lookAheadNum=0)), 0) == 7
    p = para()
    p.scale[1] = 0.0
    assert gt.GT_InitLookAheadEx(1, byref(p), 0) == 7 and "scale[1]" in gt.GTE_GetLastError()
    p = para()
    p.axisRelation[0], p.axisRelation[1] = 2, 1
    assert gt.GT_InitLookAheadEx(1, byref(p), 0) == 1 and "one-to-one" in gt.GTE_GetLastError()
    assert gt.GT_InitLookAheadEx(1, byref(para()), 0, 1) == 1  # motionMode 1
    pre = gt.TPreStartPos()
    pre.Pos[2] = float("nan")
    assert gt.GT_InitLookAheadEx(1, byref(para()), 0, 0, byref(pre)) == 7
