"""Electronic gear through ``from gtecat import gt`` (lockstep clock): manual 7.5, figure 7-10,
chapter 13 entries 24, 53-54, 87, 110-111.  The slave is compared sample by sample with the
area under the ratio in master travel (``tests/gtecat/motion/test_gear.py``'s reference), fed
with the master positions the controller reports."""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_short

import numpy as np
import pytest

from gtecat import gt
from tests.gtecat.controller.motion.test_gear import clutch_reference

from .conftest import bring_up

MOVING = 1 << 10


def up(eni: str = "manual_fig5_2.eni", axes: tuple[int, ...] = (1, 2)) -> None:
    bring_up(eni, clock="lockstep")
    for a in axes:
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
        assert gt.GT_ZeroPos(a, 1) == 0, gt.GTE_GetLastError()


def read(fn, axis: int) -> float:
    v = c_double()
    assert fn(axis, byref(v)) == 0, gt.GTE_GetLastError()
    return v.value


def pos(axis: int) -> float:
    return read(gt.GT_GetPrfPos, axis)


def moving(axis: int) -> bool:
    s = c_long()
    assert gt.GT_GetSts(axis, byref(s)) == 0
    return bool(s.value & MOVING)


def jog(axis: int, vel: float, acc: float = 1.0) -> None:
    assert gt.GT_PrfJog(axis) == 0, gt.GTE_GetLastError()
    prm = gt.TJogPrm()
    assert gt.GT_GetJogPrm(axis, byref(prm)) == 0
    prm.acc, prm.dec = acc, acc
    assert gt.GT_SetJogPrm(axis, byref(prm)) == 0
    assert gt.GT_SetVel(axis, vel) == 0
    assert gt.GT_Update(1 << (axis - 1)) == 0, gt.GTE_GetLastError()


def trap_to(axis: int, target: int, vel: float = 10.0, acc: float = 0.5) -> None:
    if gt.GT_PrfTrap(axis) != 0:
        raise AssertionError(gt.GTE_GetLastError())
    prm = gt.TTrapPrm()
    assert gt.GT_GetTrapPrm(axis, byref(prm)) == 0
    prm.acc, prm.dec = acc, acc
    assert gt.GT_SetTrapPrm(axis, byref(prm)) == 0
    assert gt.GT_SetPos(axis, target) == 0 and gt.GT_SetVel(axis, vel) == 0
    assert gt.GT_Update(1 << (axis - 1)) == 0, gt.GTE_GetLastError()


def gear(slave: int, master: int, me: int, se: int, slope: int, dir: int = 0, **kw) -> None:
    assert gt.GT_PrfGear(slave, dir) == 0, gt.GTE_GetLastError()
    mtype = kw.get("mtype", gt.GEAR_MASTER_PROFILE)
    item = kw.get("item", 0)
    assert gt.GT_SetGearMaster(slave, master, mtype, item) == 0, gt.GTE_GetLastError()
    assert gt.GT_SetGearRatio(slave, me, se, slope) == 0, gt.GTE_GetLastError()


def trace(n: int, axes=(1, 2), extra=None) -> np.ndarray:
    rows = []
    for _ in range(n):
        gt.GTE_Wait(1)
        row = [pos(a) for a in axes]
        if extra is not None:
            row.append(extra())
        rows.append(row)
    return np.array(rows)


def rc_reason(rc: int, expected: int, *words: str) -> None:
    reason = gt.GTE_GetLastError()
    assert rc == expected, reason
    for w in words:
        assert w in reason, reason


# --- shapes -----------------------------------------------------------------------------------
def test_clutch_zone_in_master_travel_behind_a_trap_master():
    """Master: a Trap move (speed changes); slave 3:2 engaged over 3000 master pulses."""
    up()
    trap_to(1, 20000, vel=20, acc=0.25)
    gear(2, 1, 3, 2, 3000)
    assert gt.GT_GearStart(0b10) == 0, gt.GTE_GetLastError()
    out = trace(1200)
    np.testing.assert_allclose(out[:, 1], clutch_reference(out[:, 0], 0, 2 / 3, 3000), atol=1e-8)
    assert out[-1, 0] == 20000 and out[-1, 1] == pytest.approx(1000 + 2 / 3 * 17000)
    assert moving(2) and not moving(1)  # a gear never ends by itself
    ratio = [c_long() for _ in range(3)]
    assert gt.GT_GetGearRatio(2, *(byref(r) for r in ratio)) == 0
    assert [r.value for r in ratio] == [3, 2, 3000]


def test_figure_7_10_ratio_changed_during_motion_through_a_second_clutch():
    """Clutch 1 engages 4:3 over 4000; GT_SetGearRatio(2, 1, 2000) while moving: the ratio goes
    from 3/4 to 1/2 over 2000 master pulses, then holds."""
    up()
    jog(1, 10, acc=10)  # 10 pulse/ms from the first cycle
    gear(2, 1, 4, 3, 4000)
    assert gt.GT_GearStart(0b10) == 0
    first = trace(600)
    assert np.all(np.diff(first[2:, 0]) == 10)  # the master runs at 10 pulse/ms
    np.testing.assert_allclose(first[:, 1], clutch_reference(first[:, 0], 0, 0.75, 4000))
    assert gt.GT_SetGearRatio(2, 2, 1, 2000) == 0, gt.GTE_GetLastError()
    second = trace(400)
    x = second[:, 0] - first[-1, 0]
    np.testing.assert_allclose(
        second[:, 1], first[-1, 1] + clutch_reference(x, 0.75, 0.5, 2000), atol=1e-9
    )
    v = read(gt.GT_GetPrfVel, 2)
    assert v == pytest.approx(5.0)


def test_direction_1_follows_only_positive_master_motion():
    up()
    trap_to(1, 1000, vel=10, acc=1)
    gear(2, 1, 1, 1, 0, dir=1)
    assert gt.GT_GearStart(0b10) == 0
    rows = list(trace(120))
    trap_to(1, 0, vel=10, acc=1)  # master goes back: the slave stands
    rows += list(trace(120))
    trap_to(1, 400, vel=10, acc=1)  # and forward again: the slave moves on
    rows += list(trace(60))
    out = np.array(rows)
    inc = np.diff(np.concatenate([[0.0], out[:, 0]]))
    np.testing.assert_allclose(out[:, 1], np.cumsum(np.clip(inc, 0, None)), atol=1e-9)
    assert out[-1, 1] == pytest.approx(1400)


def test_master_types_encoder_and_axis_are_read_as_the_controller_has_them():
    """GEAR_MASTER_ENCODER: the slave uses the encoder as known at the start of its cycle
    (the last exchange's 6064h); GEAR_MASTER_AXIS item 0/1: the axis planned / encoder."""
    up(eni="twelve_axes.eni", axes=(1, 2, 3, 4))
    gear(2, 1, 1, 1, 0, mtype=gt.GEAR_MASTER_ENCODER)
    gear(3, 1, 2, 1, 0, mtype=gt.GEAR_MASTER_AXIS, item=0)
    gear(4, 1, 1, 2, 0, mtype=gt.GEAR_MASTER_AXIS, item=1)
    e0 = read(gt.GT_GetEncPos, 1)
    a0 = read(gt.GT_GetAxisPrfPos, 1)
    jog(1, 20, acc=0.5)
    assert gt.GT_GearStart(0b1110) == 0, gt.GTE_GetLastError()
    rows = []
    for _ in range(100):
        gt.GTE_Wait(1)
        rows.append([read(gt.GT_GetEncPos, 1), read(gt.GT_GetAxisPrfPos, 1)])
        rows[-1] += [read(gt.GT_GetAxisEncPos, 1), pos(2), pos(3), pos(4)]
    out = np.array(rows)
    enc_prev = np.concatenate([[e0], out[:-1, 0]])
    np.testing.assert_allclose(out[:, 3], enc_prev - e0)
    np.testing.assert_allclose(out[:, 4], (out[:, 1] - a0) / 2)
    np.testing.assert_allclose(out[:, 5], 2 * (enc_prev - e0))
    assert out[-1, 0] > 1000  # the drive did follow
    for a, t in ((2, gt.GEAR_MASTER_ENCODER), (3, gt.GEAR_MASTER_AXIS), (4, gt.GEAR_MASTER_AXIS)):
        idx, typ, item = c_short(), c_short(), c_short()
        assert gt.GT_GetGearMaster(a, byref(idx), byref(typ), byref(item)) == 0
        assert (idx.value, typ.value, item.value) == (1, t, 1 if a == 4 else 0)


def test_a_master_numbered_above_its_slave_lags_one_cycle():
    """7.5.2 note: axes are planned in number order; slave 1 sees master 2 one cycle late."""
    up()
    jog(2, 10, acc=1)
    gear(1, 2, 1, 1, 0)
    assert gt.GT_GearStart(0b01) == 0
    out = trace(50)
    np.testing.assert_allclose(out[:, 0], np.concatenate([[0.0], out[:-1, 1]]))


def test_one_start_for_two_slaves_with_their_own_ratios():
    up(eni="twelve_axes.eni", axes=(1, 2, 3))
    jog(1, 30, acc=1)
    gear(2, 1, 1, 1, 0)
    gear(3, 1, 5, -2, 1000)
    assert gt.GT_GearStart(0b110) == 0
    out = trace(200, axes=(1, 2, 3))
    np.testing.assert_allclose(out[:, 1], out[:, 0])
    np.testing.assert_allclose(out[:, 2], clutch_reference(out[:, 0], 0, -0.4, 1000), atol=1e-9)


def test_gt_stop_brakes_the_slave_and_a_new_start_engages_again():
    up()
    jog(1, 10, acc=10)
    gear(2, 1, 1, 1, 0)
    assert gt.GT_GearStart(0b10) == 0
    before = trace(20)
    assert gt.GT_SetStopDec(2, 1, 1000) == 0
    assert gt.GT_Stop(0b10, 0) == 0
    out = trace(15)
    assert not moving(2) and out[-1, 1] == pytest.approx(before[-1, 1] + 10 * 10 / 2)
    mode = c_long()
    assert gt.GT_GetPrfMode(2, byref(mode)) == 0 and mode.value == 3
    assert gt.GT_GearStart(0b10) == 0, gt.GTE_GetLastError()
    out2 = trace(5)
    np.testing.assert_allclose(out2[:, 1] - out[-1, 1], out2[:, 0] - out[-1, 0])


# --- settings ----------------------------------------------------------------------------------
def test_defaults_and_settings_that_survive_a_trip_through_another_mode():
    up()
    assert gt.GT_PrfGear(2) == 0
    idx, typ, item = c_short(9), c_short(9), c_short(9)
    assert gt.GT_GetGearMaster(2, byref(idx), byref(typ), byref(item)) == 0
    assert (idx.value, typ.value, item.value) == (0, gt.GEAR_MASTER_PROFILE, 0)
    r = [c_long(9) for _ in range(3)]
    assert gt.GT_GetGearRatio(2, *(byref(x) for x in r)) == 0
    assert [x.value for x in r] == [0, 0, 0]
    assert gt.GT_SetGearMaster(2, 1) == 0  # masterType, masterItem default
    assert gt.GT_SetGearRatio(2, 7, -3, 10) == 0
    assert gt.GT_PrfTrap(2) == 0
    assert gt.GT_PrfGear(2, 1) == 0  # another dir from another mode: allowed, settings kept
    assert gt.GT_GetGearMaster(2, byref(idx), byref(typ), byref(item)) == 0
    assert (idx.value, typ.value, item.value) == (1, gt.GEAR_MASTER_PROFILE, 0)
    assert gt.GT_GetGearRatio(2, *(byref(x) for x in r)) == 0
    assert [x.value for x in r] == [7, -3, 10]
    rc_reason(gt.GT_PrfGear(2, -1), 1, "dir 1, not -1")  # entry 87 (2)
    assert gt.GT_PrfGear(2, 1) == 0
    assert gt.GTN_GetGearRatio(1, 2, *(byref(x) for x in r)) == 0 and r[0].value == 7


# --- return codes ------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "call",
    [
        lambda: gt.GT_SetGearMaster(2, 1, gt.GEAR_MASTER_PROFILE, 0),
        lambda: gt.GT_GetGearMaster(2, byref(c_short()), byref(c_short()), byref(c_short())),
        lambda: gt.GT_SetGearRatio(2, 1, 1, 0),
        lambda: gt.GT_GetGearRatio(2, byref(c_long()), byref(c_long()), byref(c_long())),
        lambda: gt.GT_GearStart(0b10),
    ],
)
@pytest.mark.long
def test_every_gear_call_returns_1_outside_gear_mode(call):
    up()
    rc_reason(call(), 1, "Trap mode", "GT_PrfGear")


def test_return_1_conditions():
    up()
    assert gt.GT_PrfGear(2, 0) == 0
    rc_reason(gt.GT_GearStart(0b10), 1, "no master")  # entry 24 (2)
    assert gt.GT_SetGearMaster(2, 1, gt.GEAR_MASTER_PROFILE, 0) == 0
    rc_reason(gt.GT_GearStart(0b10), 1, "no gear ratio")  # entry 24 (3)
    assert gt.GT_SetGearRatio(2, 1, 1, 0) == 0
    assert gt.GT_AxisOff(2) == 0
    rc_reason(gt.GT_GearStart(0b10), 1, "GT_AxisOn")
    assert gt.GT_AxisOn(2) == 0
    rc_reason(gt.GT_GearStart(0), 1, "selects no axis")
    assert gt.GT_GearStart(0b10) == 0
    rc_reason(gt.GT_GearStart(0b10), 1, "moving")
    rc_reason(gt.GT_PrfGear(2, 0), 1, "moving")  # entry 87 (1)
    rc_reason(gt.GT_SetGearMaster(2, 1, gt.GEAR_MASTER_ENCODER, 0), 1, "moving")  # 110 (1)
    assert gt.GT_SetGearRatio(2, 3, 1, 0) == 0  # allowed while moving (figure 7-10)


@pytest.mark.parametrize(
    ("call", "word"),
    [
        (lambda: gt.GT_PrfGear(2, 2), "dir"),
        (lambda: gt.GT_SetGearMaster(2, 2, gt.GEAR_MASTER_PROFILE, 0), "differ"),
        (lambda: gt.GT_SetGearMaster(2, 3, gt.GEAR_MASTER_PROFILE, 0), "masterIndex=3"),
        (lambda: gt.GT_SetGearMaster(2, 0, gt.GEAR_MASTER_PROFILE, 0), "masterIndex"),
        (lambda: gt.GT_SetGearMaster(2, 1, 4, 0), "masterType"),
        (lambda: gt.GT_SetGearMaster(2, 1, gt.GEAR_MASTER_AXIS, 2), "masterItem"),
        (lambda: gt.GT_SetGearRatio(2, 0, 1, 0), "masterEven"),
        (lambda: gt.GT_SetGearRatio(2, 1, 1, 1), "masterSlope"),
        (lambda: gt.GT_SetGearRatio(2, 1, 1, -5), "masterSlope"),
        (lambda: gt.GT_SetGearRatio(2, 1, 1.5, 0), "slaveEven"),
        (lambda: gt.GT_SetGearRatio(2, 1 << 31, 1, 0), "long"),
        (lambda: gt.GT_GearStart(1 << 4), "axis 5"),
    ],
)
def test_bad_arguments_return_7(call, word):
    up()
    assert gt.GT_PrfGear(2, 0) == 0
    rc_reason(call(), 7, word)
