"""Lead-screw compensation as a machine's setup program loads it: the drive (and so the
encoder) goes to the corrected place, the planned position stays as planned, a different
correction for each direction of travel."""

from __future__ import annotations

from ctypes import byref, c_double, c_long

from gtecat import gt


def pos(axis: int) -> tuple[float, float]:
    p, e = c_double(), c_double()
    assert gt.GT_GetPrfPos(axis, byref(p)) == 0 and gt.GT_GetEncPos(axis, byref(e)) == 0
    return p.value, e.value


def move(axis: int, target: int) -> None:
    assert gt.GT_SetPos(axis, target) == 0 and gt.GT_SetVel(axis, 20.0) == 0
    assert gt.GT_Update(1 << (axis - 1)) == 0, gt.GTE_GetLastError()
    s = c_long()
    for _ in range(2000):
        gt.GTE_Wait(5)
        gt.GT_GetSts(axis, byref(s))
        if not s.value & 1 << 10:
            gt.GTE_Wait(5)  # the drive and the encoder follow
            return
    raise AssertionError("never stopped")


def test_the_encoder_carries_the_correction_of_the_direction_travelled():
    assert gt.GT_Open(card="gts:2", clock="lockstep", log="") == 0
    assert gt.GT_AxisOn(1) == 0 and gt.GT_PrfTrap(1) == 0
    positive = (c_long * 5)(0, 10, 20, 30, 40)  # points at 0, 1000, 2000, 3000, 4000
    negative = (c_long * 5)(0, 4, 14, 24, 34)  # 6 pulses of backlash
    assert gt.GT_EnableLeadScrewComp(1, 1) == 1  # no table yet
    assert gt.GT_SetLeadScrewComp(1, 5, 0, 4000, positive, negative) == 0
    assert gt.GT_EnableLeadScrewComp(1, 1) == 0
    move(1, 1500)
    assert pos(1) == (1500.0, 1515.0)
    move(1, 5000)  # beyond the table: its end value
    assert pos(1) == (5000.0, 5040.0)
    move(1, 2500)  # coming back: the negative list
    assert pos(1) == (2500.0, 2519.0)
    assert gt.GT_EnableLeadScrewComp(1, 0) == 0
    gt.GTE_Wait(5)
    assert pos(1) == (2500.0, 2500.0)
    assert gt.GT_SetLeadScrewComp(1, 5, 0, 0, positive, negative) == 7
    assert gt.GT_SetLeadScrewComp(1, 1, 0, 100, positive, negative) == 7
