"""A gantry pair as a machine with two motors on one beam uses it (vendor GTS header:
``GT_SetGantryMode(group, master, slave, mode, syncErrorLimit)``, ``GANTRY_MODE_*``):
the slave follows every move of the master, released with ``GANTRY_MODE_NONE``."""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_short

from gtecat import gt


def pos(axis: int) -> float:
    p = c_double()
    assert gt.GT_GetPrfPos(axis, byref(p)) == 0
    return p.value


def moving(axis: int) -> bool:
    s = c_long()
    assert gt.GT_GetSts(axis, byref(s)) == 0
    return bool(s.value & 1 << 10)


def trap(axis: int, target: int) -> int:
    assert gt.GT_PrfTrap(axis) == 0
    assert gt.GT_SetTrapPrm(axis, byref(gt.TTrapPrm(acc=0.5, dec=0.5))) == 0
    assert gt.GT_SetPos(axis, target) == 0 and gt.GT_SetVel(axis, 10.0) == 0
    return gt.GT_Update(1 << (axis - 1))


def test_the_slave_moves_with_the_master_until_released():
    assert gt.GT_Open(card="gts:4", clock="lockstep", log="") == 0
    for a in (1, 2, 3):
        assert gt.GT_AxisOn(a) == 0
    assert trap(2, 300) == 0  # the slave starts 300 pulses off (kept as an offset)
    while moving(2):
        gt.GTE_Wait(1)
    mode = gt.GANTRY_MODE_OPEN_LOOP_GANTRY
    assert gt.GT_SetGantryMode(1, 1, 2, mode, 500) == 0, gt.GTE_GetLastError()
    assert trap(1, 2000) == 0
    gt.GTE_Wait(50)
    assert moving(2) and pos(2) - pos(1) == 300.0  # in step, every cycle
    while moving(1):
        gt.GTE_Wait(1)
    assert (pos(1), pos(2)) == (2000.0, 2300.0)
    m, s, md, lim = c_short(), c_short(), c_short(), c_long()
    assert gt.GT_GetGantryMode(1, byref(m), byref(s), byref(md), byref(lim)) == 0
    assert (m.value, s.value, md.value, lim.value) == (1, 2, 1, 500)
    assert gt.GT_SetGantryMode(2, 2, 3, mode) == 7  # axis 2 is in group 1
    assert gt.GT_SetGantryMode(2, 3, 3, mode) == 7
    assert gt.GT_SetGantryMode(2, 3, 4, 5) == 7
    assert trap(1, 0) == 0
    gt.GTE_Wait(5)
    assert gt.GT_SetGantryMode(1, 1, 2, gt.GANTRY_MODE_NONE) == 1  # not while moving
    while moving(1):
        gt.GTE_Wait(1)
    assert gt.GT_SetGantryMode(1, 1, 2, gt.GANTRY_MODE_NONE) == 0
    assert trap(1, 1000) == 0 and trap(2, 300) == 0  # independent again
    while moving(1) or moving(2):
        gt.GTE_Wait(1)
    assert (pos(1), pos(2)) == (1000.0, 300.0)
    assert gt.GT_GetGantryMode(1, byref(m), byref(s), byref(md), byref(lim)) == 0
    assert md.value == -1
