"""Trap, Jog, GT_Update, GT_Stop and positions through ``from gtecat import gt`` (lockstep clock).

Manual 7.1-7.3, 6.3.2, 8.2, 11.6, chapter 13 entries 26-32, 46-47, 55, 59, 62-65,
74, 77, 88, 90, 105, 113, 115, 118, 125, 127, 131, 135, 137, 138.  Profiles are
compared sample by sample with the closed-form trapezoids of
``tests/gtecat/motion/reference.py`` (written from the formulas, not the planner).
"""

from __future__ import annotations

import math
from ctypes import byref, c_double, c_int32, c_long, c_short

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat import gt
from gtecat.controller.recorder import Recorder
from tests.conftest import EXAMPLES, examples
from tests.gtecat.controller.motion.reference import Trapezoid

from .conftest import bring_up

MOVING = 1 << 10


def up(eni: str = "manual_fig5_2.eni", axes: tuple[int, ...] = (1,), **options) -> None:
    bring_up(eni, clock="lockstep", **options)
    for a in axes:
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
        assert gt.GT_ZeroPos(a, 1) == 0, gt.GTE_GetLastError()


def trap(axis: int, pos: int, vel: float, acc: float, dec: float, vs=0.0, ts=0) -> None:
    prm = gt.TTrapPrm()
    assert gt.GT_PrfTrap(axis) == 0, gt.GTE_GetLastError()
    assert gt.GT_GetTrapPrm(axis, byref(prm)) == 0
    prm.acc, prm.dec, prm.velStart, prm.smoothTime = acc, dec, vs, ts
    assert gt.GT_SetTrapPrm(axis, byref(prm)) == 0, gt.GTE_GetLastError()
    assert gt.GT_SetPos(axis, pos) == 0
    assert gt.GT_SetVel(axis, vel) == 0


def prf(axis: int = 1) -> tuple[float, float, float]:
    p, v, a = c_double(), c_double(), c_double()
    assert gt.GT_GetPrfPos(axis, byref(p)) == 0
    assert gt.GT_GetPrfVel(axis, byref(v)) == 0
    assert gt.GT_GetPrfAcc(axis, byref(a)) == 0
    return p.value, v.value, a.value


def sts(axis: int = 1) -> int:
    s = c_long()
    assert gt.GT_GetSts(axis, byref(s)) == 0
    return s.value


def run_samples(axis: int = 1, limit: int = 100_000) -> np.ndarray:
    """One cycle at a time until bit 10 clears: rows (pos, vel, acc, moving)."""
    rows = []
    while True:
        gt.GTE_Wait(1)
        p, v, a = prf(axis)
        moving = bool(sts(axis) & MOVING)
        rows.append((p, v, a, moving))
        if not moving:
            return np.array(rows)
        assert len(rows) < limit


def last_error() -> str:
    return gt.GTE_GetLastError()


# --- Trap against the closed form ----------------------------------------------------------------
def test_example_7_1_profile_sample_by_sample_without_smoothing():
    up()
    trap(1, 50000, 50, 0.25, 0.125)
    assert gt.GT_Update(1) == 0, last_error()
    out = run_samples()
    ref = Trapezoid.plan(50000, 50, 0.25, 0.125)
    n = math.ceil(ref.duration)
    assert len(out) == n == 1300  # bit 10 drops with the end sample
    t = np.arange(1, n + 1, dtype=float)
    p, v, a = ref.at(t)
    np.testing.assert_allclose(out[:, 0], p, atol=1e-9)
    np.testing.assert_allclose(out[:, 1], v, atol=1e-12)
    np.testing.assert_allclose(out[:-1, 2], a[:-1], atol=1e-12)
    assert out[-1, 0] == 50000.0 and out[-1, 1] == 0.0
    assert out[:-1, 3].all()


def test_example_7_1_profile_sample_by_sample_with_25_ms_smoothing():
    up()
    trap(1, 50000, 50, 0.25, 0.125, ts=25)
    assert gt.GT_Update(1) == 0
    out = run_samples()
    ref = Trapezoid.plan(50000, 50, 0.25, 0.125)
    assert len(out) == 1325  # the moving average adds smoothTime
    t = np.arange(1, len(out) + 1, dtype=float)
    np.testing.assert_allclose(out[:, 0], ref.smoothed_exact(t, 25.0), atol=1e-7)
    assert out[-1, 0] == 50000.0
    # smoothing: the acceleration ramps over 25 ms (jerk acc/25), never a step
    assert np.max(np.abs(np.diff(out[:-1, 2]))) <= 0.25 / 25 + 1e-12
    assert np.max(out[:, 1]) <= 50.0 + 1e-12 and np.all(np.diff(out[:, 0]) >= 0)


@pytest.mark.parametrize(
    ("dist", "vel", "acc", "dec", "vs"), [(300, 50, 0.5, 0.25, 0), (-7777, 20, 1, 2, 3)]
)
def test_short_and_negative_moves_end_exactly_with_the_analytic_duration(dist, vel, acc, dec, vs):
    up()
    trap(1, dist, vel, acc, dec, vs=vs)
    assert gt.GT_Update(1) == 0
    out = run_samples()
    ref = Trapezoid.plan(dist, vel, acc, dec, vs)
    assert len(out) == math.ceil(ref.duration - 1e-9)
    p, v, _ = ref.at(np.arange(1, len(out) + 1, dtype=float))
    np.testing.assert_allclose(out[:, 0], p, atol=1e-8)
    np.testing.assert_allclose(out[:-1, 1], v[:-1], atol=1e-12)
    assert out[-1, 0] == dist
    if dist == 300:
        assert ref.vp < vel and np.max(out[:, 1]) < vel  # a triangle: never reaches the speed


def test_planned_position_reaches_607a_and_the_drive_follows():
    up()
    rec = Recorder(gt.GTE_Controller(), ["axis1.prf", "0:0x607A:0", "axis1.enc"]).start()
    trap(1, 20000, 40, 1, 1)
    assert gt.GT_Update(1) == 0
    run_samples()
    gt.GTE_Wait(30)
    rec.stop()
    prf_col, target, enc = (rec.column(n) for n in ("axis1.prf", "0:0x607A:0", "axis1.enc"))
    np.testing.assert_array_equal(target, np.round(prf_col))  # scale 0, offset 0
    assert enc[-1] == 20000
    e = c_double()
    assert gt.GT_GetAxisError(1, byref(e)) == 0 and e.value == 0.0


def test_target_and_speed_changed_during_the_move():
    up()
    trap(1, 30000, 40, 0.5, 0.5)
    assert gt.GT_Update(1) == 0
    gt.GTE_Wait(300)  # cruising at 40 since 80 ms
    _, v, _ = prf()
    assert v == pytest.approx(40)
    assert gt.GT_SetVel(1, 20) == 0 and gt.GT_Update(1) == 0  # slower
    gt.GTE_Wait(41)
    assert prf()[1] == pytest.approx(20)
    assert gt.GT_SetPos(1, 5000) == 0 and gt.GT_Update(1) == 0  # behind: brake, come back
    out = run_samples()
    assert out[-1, 0] == 5000.0
    assert np.max(np.abs(np.diff(out[:, 1]))) <= 0.5 + 1e-9  # never more than acc/dec per ms
    assert np.max(np.abs(out[:, 1])) <= 20 + 1e-9
    pos = c_long()
    assert gt.GT_GetPos(1, byref(pos)) == 0 and pos.value == 5000
    vel = c_double()
    assert gt.GT_GetVel(1, byref(vel)) == 0 and vel.value == 20


def test_update_starts_several_axes_in_the_same_cycle_and_is_all_or_nothing():
    up(axes=(1, 2))
    trap(1, 1000, 10, 1, 1)
    trap(2, -1000, 10, 1, 1)
    assert gt.GT_Update(0b11) == 0
    gt.GTE_Wait(1)
    assert prf(1)[0] == 0.5 and prf(2)[0] == -0.5
    run_samples(1)
    gt.GTE_Wait(5)
    assert gt.GT_AxisOff(2) == 0
    assert gt.GT_SetPos(1, 0) == 0
    assert gt.GT_Update(0b11) == 1 and "axis 2" in last_error()
    gt.GTE_Wait(5)
    assert prf(1)[0] == 1000.0  # axis 1 did not start either
    assert gt.GT_Update(1 << 5) == 7  # axis 6 does not exist


# --- Jog -----------------------------------------------------------------------------------------
def test_example_7_2_jog_speed_changed_on_the_fly():
    up()
    jog = gt.TJogPrm()
    assert gt.GT_PrfJog(1) == 0
    assert gt.GT_GetJogPrm(1, byref(jog)) == 0
    jog.acc, jog.dec = 0.0625, 0.0625
    assert gt.GT_SetJogPrm(1, byref(jog)) == 0
    assert gt.GT_SetVel(1, 100) == 0 and gt.GT_Update(1) == 0
    vels = []
    changed_at = None
    for k in range(1, 4000):
        gt.GTE_Wait(1)
        p, v, _ = prf()
        vels.append(v)
        if changed_at is None and p > 100000:
            assert gt.GT_SetVel(1, 50) == 0 and gt.GT_Update(1) == 0
            changed_at = k
    vels = np.array(vels)
    assert vels[1599] == pytest.approx(100) and vels[1598] < 100  # 100 / 0.0625 = 1600 ms
    assert changed_at is not None
    # from 100 down to 50 at 0.0625 pulse/ms²: 800 ms, then steady at 50
    assert vels[changed_at + 799] == pytest.approx(50) and vels[changed_at + 790] > 50
    assert np.all(vels[changed_at + 800 :] == pytest.approx(50))
    assert sts() & MOVING
    assert gt.GT_GetJogPrm(1, byref(jog)) == 1 and "moving" in last_error()  # entry 55
    assert gt.GT_Stop(1, 0) == 0
    out = run_samples()
    # smooth stop at decSmoothStop = 1 pulse/ms² from 50: 50 ms
    assert len(out) == 50 and out[-1, 1] == 0.0


def test_jog_negative_speed_and_smoothing_keep_acceleration_bounded():
    up()
    jog = gt.TJogPrm()
    jog.acc, jog.dec, jog.smooth = 0.5, 0.25, 0.9
    assert gt.GT_PrfJog(1) == 0 and gt.GT_SetJogPrm(1, byref(jog)) == 0
    assert gt.GT_SetVel(1, -30) == 0 and gt.GT_Update(1) == 0
    acc = []
    for _ in range(400):
        gt.GTE_Wait(1)
        acc.append(prf()[2])
    assert prf()[1] == pytest.approx(-30, abs=1e-6)
    assert max(abs(a) for a in acc) <= 0.5 + 1e-12
    assert abs(acc[0]) < 0.5  # the filter makes the acceleration rise gradually


# --- GT_Stop -------------------------------------------------------------------------------------
@pytest.mark.parametrize(("option", "dec"), [(0, 1.0), (1, 1000.0)])
def test_stop_smooth_and_abrupt_use_the_table_4_4_decelerations(option, dec):
    up()
    smooth, abrupt = c_double(), c_double()
    assert gt.GT_GetStopDec(1, byref(smooth), byref(abrupt)) == 0
    assert (smooth.value, abrupt.value) == (1.0, 1000.0)
    trap(1, 100000, 20, 1, 1)
    assert gt.GT_Update(1) == 0
    gt.GTE_Wait(100)
    p0, v0, _ = prf()
    assert v0 == 20
    assert gt.GT_Stop(1, option) == 0
    out = run_samples()
    assert len(out) == math.ceil(v0 / dec)
    assert out[-1, 0] == pytest.approx(p0 + v0 * v0 / (2 * dec))
    assert not sts() & (3 << 7)  # GT_Stop does not set the IO-stop flags (bits 7/8)
    assert gt.GT_Update(1) == 0  # and the axis may move again at once


def test_set_stop_dec_and_stop_mask_ignores_missing_axes():
    up()
    assert gt.GT_SetStopDec(1, 2.5, 40) == 0
    d1, d2 = c_double(), c_double()
    assert gt.GT_GetStopDec(1, byref(d1), byref(d2)) == 0 and (d1.value, d2.value) == (2.5, 40)
    for bad in ((0, 10), (1, 32768), (-1, 1)):
        assert gt.GT_SetStopDec(1, *bad) == 7
    trap(1, 100000, 10, 1, 1)
    assert gt.GT_Update(1) == 0
    gt.GTE_Wait(20)
    assert gt.GT_Stop(0xFFF, 0) == 0  # "stop everything", axes 3..12 absent
    out = run_samples()
    assert len(out) == 4  # 10 / 2.5


def test_stop_takes_bit_31_of_its_mask_either_way():
    """GT_Stop(long mask, long option): a bit pattern; bit 31 (axis 32) comes as the C long
    -2^31 or as the word 2^31, as GT_Update takes it; past 32 bits, 7 quoting the value the
    caller passed."""
    up()
    trap(1, 100000, 10, 1, 1)
    assert gt.GT_Update(1) == 0
    for mask in (-(1 << 31), 1 << 31, 0xAA000000, -1, (1 << 32) - 1):
        assert gt.GT_Stop(mask, 0) == 0, gt.GTE_GetLastError()
        assert gt.GT_Stop(0, mask) == 0, gt.GTE_GetLastError()
    for mask in (1 << 32, -(1 << 31) - 1):
        assert gt.GT_Stop(mask, 0) == 7
        assert f"mask={mask} out of range" in gt.GTE_GetLastError()
    assert gt.GT_Stop(1, 1 << 32) == 7 and "option=4294967296" in gt.GTE_GetLastError()
    # the implementation itself (called with what the argument layer hands over, or not)
    from gtecat.gt.motion_calls import mask_arg

    assert mask_arg("mask", -(1 << 31)) == mask_arg("mask", 1 << 31) == 0x80000000


# --- mode rules (chapter 13 return 1) ------------------------------------------------------------
def test_mode_rules_refuse_with_a_reason():
    up()
    prm, jog = gt.TTrapPrm(), gt.TJogPrm()
    mode = c_long()
    assert gt.GT_GetPrfMode(1, byref(mode)) == 0 and mode.value == 0  # Trap after reset
    assert gt.GT_PrfJog(1) == 0
    assert gt.GT_GetPrfMode(1, byref(mode)) == 0 and mode.value == 1
    for call in (
        lambda: gt.GT_SetTrapPrm(1, byref(prm)),
        lambda: gt.GT_GetTrapPrm(1, byref(prm)),
        lambda: gt.GT_SetPos(1, 10),
        lambda: gt.GT_GetPos(1, byref(c_long())),
    ):
        assert call() == 1 and "GT_PrfTrap" in last_error()
    assert gt.GT_SetVel(1, -5) == 0  # Jog takes a signed speed
    assert gt.GT_PrfTrap(1) == 0
    assert gt.GT_SetJogPrm(1, byref(jog)) == 1 and "GT_PrfJog" in last_error()
    assert gt.GT_GetJogPrm(1, byref(jog)) == 1
    trap(1, 10000, 10, 0.5, 0.5)
    assert gt.GT_Update(1) == 0
    gt.GTE_Wait(5)
    for call in (
        lambda: gt.GT_PrfJog(1),
        lambda: gt.GT_PrfTrap(1),
        lambda: gt.GT_SetTrapPrm(1, byref(prm)),
        lambda: gt.GT_ZeroPos(1, 1),
        lambda: gt.GT_SetPrfPos(1, 0),
        lambda: gt.GT_ProfileScale(1, 2, 1),
        lambda: gt.GT_EncScale(1, 2, 1),
        lambda: gt.GT_SetPosScale(1, 2),
    ):
        assert call() == 1 and "moving" in last_error()
    assert gt.GT_GetTrapPrm(1, byref(prm)) == 0  # entry 74 does not refuse while moving
    assert gt.GT_SetPos(1, 20000) == 0 and gt.GT_SetVel(1, 12) == 0  # next GT_Update
    assert gt.GT_SynchAxisPos(0) == 1 and "mask" in last_error()


def test_update_refused_when_servo_off():
    bring_up(clock="lockstep")
    trap(1, 1000, 10, 1, 1)
    assert gt.GT_Update(1) == 1
    assert "axis 1" in last_error() and "GT_AxisOn" in last_error()
    assert gt.GT_AxisOn(1) == 0
    assert gt.GT_Update(1) == 0
    gt.GTE_Wait(10)
    assert gt.GT_AxisOff(1) == 0
    assert not sts() & (MOVING | 1 << 9)  # servo off drops the motion


def test_update_refused_outside_csp():
    up("twelve_axes.eni")
    assert gt.GT_SetEcatAxisMode(1, 9) == 0
    trap(1, 1000, 10, 1, 1)
    assert gt.GT_Update(1) == 1 and "mode 9" in last_error()
    assert gt.GT_SetEcatAxisMode(1, 8) == 0
    gt.GTE_Wait(3)
    assert gt.GT_Update(1) == 0


def test_parameter_ranges_return_7():
    up()
    prm = gt.TTrapPrm()
    assert gt.GT_PrfTrap(1) == 0
    for acc, dec, vs, ts in ((0, 1, 0, 0), (1, -1, 0, 0), (1, 1, -1, 0), (1, 1, 0, 51)):
        prm.acc, prm.dec, prm.velStart, prm.smoothTime = acc, dec, vs, ts
        assert gt.GT_SetTrapPrm(1, byref(prm)) == 7
    prm.acc, prm.dec, prm.velStart, prm.smoothTime = 1, 0, 0, 50  # dec 0 = "not set" = acc
    assert gt.GT_SetTrapPrm(1, byref(prm)) == 0
    back = gt.TTrapPrm()
    assert gt.GT_GetTrapPrm(1, byref(back)) == 0 and back.dec == 1 and back.smoothTime == 50
    assert gt.GT_SetTrapPrm(1, byref(c_double())) == 7  # not a TTrapPrm
    assert gt.GT_SetPos(1, 1073741824) == 7 and gt.GT_SetPos(1, -1073741823) == 0
    assert gt.GT_SetVel(1, 0) == 7 and gt.GT_SetVel(1, float("nan")) == 7
    jog = gt.TJogPrm()
    assert gt.GT_PrfJog(1) == 0
    jog.acc, jog.dec, jog.smooth = 1, 1, 1.0
    assert gt.GT_SetJogPrm(1, byref(jog)) == 7
    assert gt.GT_PrfTrap(9) == 7


def test_update_without_speed_is_refused():
    up()
    assert gt.GT_PrfTrap(1) == 0 and gt.GT_SetPos(1, 100) == 0
    assert gt.GT_Update(1) == 1 and "GT_SetVel" in last_error()


# --- positions -----------------------------------------------------------------------------------
def test_count_forms_and_clock():
    up("twelve_axes.eni", axes=(1, 2, 3))
    trap(2, 500, 10, 1, 1)
    assert gt.GT_Update(2) == 0
    gt.GTE_Wait(200)
    values = (c_double * 3)()
    clock = c_int32()
    assert gt.GT_GetPrfPos(1, values, 3, byref(clock)) == 0
    assert list(values) == [0.0, 500.0, 0.0]
    now = c_int32()
    gt.GT_GetClock(byref(now))
    assert clock.value == now.value > 0
    modes = [9, 9]
    assert gt.GT_GetPrfMode(11, modes, 2) == 0 and modes == [0, 0]
    enc = np.zeros(8)
    assert gt.GT_GetEncPos(1, enc, 8) == 0 and enc[1] == 500.0
    assert gt.GT_GetEncPos(1, np.zeros(9), 9) == 7  # at most 8 encoders at once
    assert gt.GT_GetEncVel(1, np.zeros(8), 8) == 0
    assert gt.GT_GetPrfPos(12, (c_double * 2)(), 2) == 7  # axis 13 does not exist
    assert gt.GT_GetPrfPos(1, (c_double * 2)(), 3) == 7  # array too small


def test_axis_values_follow_profile_and_encoder_scaling():
    up()
    assert gt.GT_ProfileScale(1, 2, 1) == 0  # 2 profile pulses = 1 axis pulse
    assert gt.GT_ProfileScale(1, 1, 2) == 7  # |alpha| >= |beta|
    assert gt.GT_ProfileScale(1, 0, 1) == 7 and gt.GT_EncScale(1, 40000, 1) == 7
    trap(1, 4000, 10, 1, 1)
    assert gt.GT_Update(1) == 0
    run_samples()
    gt.GTE_Wait(20)
    v = c_double()
    assert gt.GT_GetPrfPos(1, byref(v)) == 0 and v.value == 4000
    assert gt.GT_GetAxisPrfPos(1, byref(v)) == 0 and v.value == 2000
    assert gt.GT_GetEncPos(1, byref(v)) == 0 and v.value == 2000  # the drive went 2000
    assert gt.GT_GetAxisError(1, byref(v)) == 0 and v.value == 0
    assert gt.GT_EncScale(1, 4, 1) == 0
    assert gt.GT_GetAxisEncPos(1, byref(v)) == 0 and v.value == 2000  # no jump
    trap(1, 0, 10, 1, 1)
    assert gt.GT_Update(1) == 0
    run_samples()
    gt.GTE_Wait(20)
    assert gt.GT_GetAxisEncPos(1, byref(v)) == 0 and v.value == 2000 - 2000 / 4
    assert gt.GT_GetEncPos(1, byref(v)) == 0 and v.value == 0


def test_set_prf_pos_and_set_enc_pos_then_synch_axis_pos():
    up()
    v = c_double()
    assert gt.GT_SetPrfPos(1, 1000) == 0
    assert gt.GT_SetEncPos(1, -50) == 0
    gt.GTE_Wait(2)
    assert gt.GT_GetPrfPos(1, byref(v)) == 0 and v.value == 1000
    assert gt.GT_GetAxisPrfPos(1, byref(v)) == 0 and v.value == 0  # not yet (11.6)
    assert gt.GT_GetEncPos(1, byref(v)) == 0 and v.value == -50
    assert gt.GT_GetAxisEncPos(1, byref(v)) == 0 and v.value == 0
    assert gt.GT_SynchAxisPos(1) == 0
    gt.GTE_Wait(20)
    assert gt.GT_GetAxisPrfPos(1, byref(v)) == 0 and v.value == 1000
    assert gt.GT_GetAxisEncPos(1, byref(v)) == 0 and v.value == -50
    assert gt.GT_GetAxisError(1, byref(v)) == 0 and v.value == 1050
    enc = c_long()
    assert gt.GT_GetEcatEncPos(1, byref(enc)) == 0 and enc.value == 0  # the drive never moved
    # a move of +500 moves every reading by +500
    trap(1, 1500, 10, 1, 1)
    assert gt.GT_Update(1) == 0
    run_samples()
    gt.GTE_Wait(20)
    assert gt.GT_GetEcatEncPos(1, byref(enc)) == 0 and enc.value == 500
    assert gt.GT_GetEncPos(1, byref(v)) == 0 and v.value == 450


def test_zero_pos_zeroes_everything_without_moving_the_drive():
    up()
    trap(1, 3000, 10, 1, 1)
    assert gt.GT_Update(1) == 0
    run_samples()
    gt.GTE_Wait(20)
    assert gt.GT_ZeroPos(1, 1) == 0
    gt.GTE_Wait(20)
    v = c_double()
    for call in (gt.GT_GetPrfPos, gt.GT_GetAxisPrfPos, gt.GT_GetEncPos, gt.GT_GetAxisEncPos):
        assert call(1, byref(v)) == 0 and v.value == 0, call.__name__
    enc = c_long()
    assert gt.GT_GetEcatEncPos(1, byref(enc)) == 0 and enc.value == 3000
    pos = c_long()
    assert gt.GT_GetPos(1, byref(pos)) == 0 and pos.value == 0  # no surprise move on GT_Update


def test_enc_sns_and_enc_off():
    up()
    v = c_double()
    assert gt.GT_EncSns(0b1) == 0  # encoder 1 counts the other way
    trap(1, 1000, 10, 1, 1)
    assert gt.GT_Update(1) == 0
    run_samples()
    gt.GTE_Wait(20)
    assert gt.GT_GetEncPos(1, byref(v)) == 0 and v.value == -1000
    assert gt.GT_EncSns(0) == 0 and gt.GT_SetEncPos(1, 1000) == 0 and gt.GT_SynchAxisPos(1) == 0
    assert gt.GT_EncOff(1) == 0  # the pulse counter: what the controller sends (607Ah)
    trap(1, 5000, 40, 20, 20)  # faster than the motor can accelerate: 6064h lags
    assert gt.GT_Update(1) == 0
    lag = []
    for _ in range(30):
        gt.GTE_Wait(1)
        p, e, enc = c_double(), c_double(), c_long()
        gt.GT_GetAxisPrfPos(1, byref(p))
        gt.GT_GetEncPos(1, byref(e))
        gt.GT_GetEcatEncPos(1, byref(enc))
        assert e.value == round(p.value)
        lag.append(p.value - enc.value)
    assert max(lag) > 10
    assert gt.GT_EncOn(1) == 0


def test_homing_then_csp_positions_are_the_drives():
    """Example 5-2 with homing_probe: after homing the controller's positions read 6064h."""
    machine = str(EXAMPLES / "homing_probe_machine.toml")
    bring_up("homing_probe.eni", clock="lockstep", machine=machine)
    assert gt.GT_AxisOn(1) == 0
    assert gt.GT_ZeroPos(1, 1) == 0
    assert gt.GT_SetHomingMode(1, 6) == 0
    assert gt.GT_SetEcatHomingPrm(1, 3, 5000, 3000, 100000, 0, 0) == 0
    assert gt.GT_StartEcatHoming(1) == 0
    assert not sts() & MOVING  # the drive homes; the profile does not plan
    st = c_short()
    for _ in range(20000):
        gt.GTE_Wait(1)
        gt.GT_GetEcatHomingStatus(1, byref(st))
        if st.value == 3:
            break
    assert st.value == 3
    assert gt.GT_SetHomingMode(1, 8) == 0
    gt.GTE_Wait(5)
    v, enc = c_double(), c_long()
    gt.GT_GetEcatEncPos(1, byref(enc))
    for call in (gt.GT_GetPrfPos, gt.GT_GetEncPos, gt.GT_GetAxisPrfPos):
        assert call(1, byref(v)) == 0 and v.value == pytest.approx(enc.value, abs=1), call.__name__
    trap(1, 2000, 10, 1, 1)
    assert gt.GT_Update(1) == 0
    run_samples()
    gt.GTE_Wait(30)
    gt.GT_GetEcatEncPos(1, byref(enc))
    assert enc.value == 2000


# --- property: any move through GT ends exactly, never overshoots, respects the limits ----------
@settings(max_examples=examples(12, 4), deadline=None)
@given(
    st.lists(
        st.tuples(
            st.integers(-20_000, 20_000),  # target
            st.floats(5, 80),  # vel
            st.floats(0.2, 5),  # acc
            st.floats(0.2, 5),  # dec
            st.integers(0, 50),  # smoothTime
        ),
        min_size=1,
        max_size=3,
    )
)
def test_random_moves_end_on_target_without_overshoot(moves):
    gt.GT_Close()
    up()
    for target, vel, acc, dec, ts in moves:
        start = prf()[0]
        trap(1, target, vel, acc, dec, ts=ts)
        assert gt.GT_Update(1) == 0, last_error()
        out = run_samples()
        assert out[-1, 0] == target
        lo, hi = min(start, target), max(start, target)
        assert np.all((out[:, 0] >= lo) & (out[:, 0] <= hi))  # no overshoot
        assert np.max(np.abs(out[:, 1])) <= vel + 1e-9
        assert np.max(np.abs(out[:, 2])) <= max(acc, dec) + 1e-9


def test_pos_scale_re_expresses_positions_without_moving_the_drive():
    """GT_SetPosScale(axis, 6): 64 drive counts per pulse (entry 117: 23 bits seen as 17)."""
    up()
    trap(1, 6400, 20, 1, 1)
    assert gt.GT_Update(1) == 0
    run_samples()
    gt.GTE_Wait(20)
    assert gt.GT_SetPosScale(1, 6) == 0
    gt.GTE_Wait(5)
    v, enc = c_double(), c_long()
    for call in (gt.GT_GetPrfPos, gt.GT_GetAxisPrfPos, gt.GT_GetEncPos, gt.GT_GetAxisEncPos):
        assert call(1, byref(v)) == 0 and v.value == 100, call.__name__
    assert gt.GT_GetEcatEncPos(1, byref(enc)) == 0 and enc.value == 6400  # did not move
    trap(1, 150, 1, 0.1, 0.1)
    assert gt.GT_Update(1) == 0
    run_samples()
    gt.GTE_Wait(30)
    assert gt.GT_GetEcatEncPos(1, byref(enc)) == 0 and enc.value == 9600  # 50 pulses = 3200
    assert gt.GT_GetEncPos(1, byref(v)) == 0 and v.value == 150
