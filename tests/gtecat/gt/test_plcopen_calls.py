"""Single-call moves as the vendor's EtherCAT Qt demo calls them: ``GTN_MoveVelocity(core,
axis, &prm)`` from its jog buttons (``direction`` 0 for jog+, 1 for jog-, vel 10, acc and
dec 1, jerks 1) then ``GTN_Stop``; ``GTN_MoveAbsolute`` with ``TMoveAbsolutePrm`` (vendor
GTN header for both layouts)."""

from __future__ import annotations

import ctypes
from ctypes import byref, c_double, c_long

from gtecat import gt
from gtecat.native import header

from .conftest import bring_up

MOVING = 1 << 10


def prf(axis: int) -> tuple[float, float]:
    p, v = c_double(), c_double()
    assert gt.GT_GetPrfPos(axis, byref(p)) == 0 and gt.GT_GetPrfVel(axis, byref(v)) == 0
    return p.value, v.value


def moving(axis: int) -> bool:
    s = c_long()
    assert gt.GT_GetSts(axis, byref(s)) == 0
    return bool(s.value & MOVING)


def test_layouts_and_header():
    v, a = gt.TMoveVelocityPrm, gt.TMoveAbsolutePrm
    assert (v.direction.offset, ctypes.sizeof(v)) == (40, 48)
    assert (a.pos.offset, a.vel.offset, a.percent.offset, ctypes.sizeof(a)) == (0, 8, 32, 40)
    text = header.render()
    assert "short GTN_MoveVelocity(short core, short profile, TMoveVelocityPrm *pPrm);" in text


def test_the_demo_jog_buttons():
    bring_up(clock="lockstep")
    assert gt.GTN_AxisOn(1, 1) == 0
    prm = gt.TMoveVelocityPrm(vel=10, acc=1, dec=1, jerkBegin=1, jerkEnd=1, direction=1)
    assert gt.GTN_MoveVelocity(1, 1, byref(prm)) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(20)
    pos, vel = prf(1)
    assert vel == -10.0 and moving(1)
    assert pos == -(10 * 10 / 2 + 10 * 10)  # 10 ms of ramp at 1 pulse/ms², then 10 at speed
    prm.direction, prm.vel = 0, 5  # jog+ while moving: the speed turns round on the fly
    assert gt.GTN_MoveVelocity(1, 1, byref(prm)) == 0
    gt.GTE_Wait(30)
    assert prf(1)[1] == 5.0
    assert gt.GTN_Stop(1, 1, 0) == 0
    gt.GTE_Wait(10)
    assert not moving(1)
    back = gt.TMoveVelocityPrm()
    assert gt.GTN_GetMoveVelocity(1, 1, byref(back)) == 0
    assert (back.vel, back.direction, back.jerkEnd) == (5.0, 0, 1.0)
    prm.direction = 2
    assert gt.GTN_MoveVelocity(1, 1, byref(prm)) == 7
    prm.direction, prm.vel = 0, 0.0
    assert gt.GTN_MoveVelocity(1, 1, byref(prm)) == 7


def test_move_absolute_starts_at_once_and_ends_on_the_target():
    bring_up(clock="lockstep")
    assert gt.GT_AxisOn(2) == 0
    prm = gt.TMoveAbsolutePrm(pos=5000, vel=20.0, acc=0.5, dec=0.25, percent=0)
    assert gt.GT_MoveAbsolute(2, byref(prm)) == 0, gt.GTE_GetLastError()
    ms = 0
    while moving(2) or ms == 0:
        gt.GTE_Wait(1)
        ms += 1
    assert prf(2) == (5000.0, 0.0)
    # trapezoid: 40 ms up, 80 ms down, the rest at 20 pulse/ms
    cruise = (5000 - 20 * 40 / 2 - 20 * 80 / 2) / 20
    assert abs(ms - (40 + 80 + cruise)) <= 2
    assert gt.GT_GetMoveAbsolute(2, byref(back := gt.TMoveAbsolutePrm())) == 0
    assert (back.pos, back.dec) == (5000, 0.25)
    assert gt.GT_MoveVelocity(2, byref(gt.TMoveVelocityPrm(vel=1, acc=1))) == 0
    assert gt.GT_MoveAbsolute(2, byref(prm)) == 1  # moving in Jog: GT_PrfTrap refuses
    prm.percent = 101
    assert gt.GT_MoveAbsolute(2, byref(prm)) == 7
