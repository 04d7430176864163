"""Buffered FIFO commands and the G0 lines as a dispenser or cutting cell calls them: a line, an
output switched where the path gets there (``GTN_BufDoBit(core, crd, MC_GPO, index, value,
fifo)``, vendor GTN header), a DAC value (``GT_BufDA``), limit switches off and on around
a move onto a switch (``GT_BufLmtsOff/On``), and the remaining entries
(``GT_GetRemainderSegNum``); vendor GTS header for the prototypes."""

from __future__ import annotations

from ctypes import byref, c_double, c_int32, c_long, c_short

from gtecat import gt
from gtecat.drives.machine import AxisMachine, MachineDescription


def card(axes=(1, 2, 3), machine: MachineDescription | None = None) -> None:
    assert gt.GT_Open(card="gts:4", machine=machine, clock="lockstep", log="") == 0
    for a in axes:
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
    prm = gt.TCrdPrm()
    prm.dimension, prm.synVelMax, prm.synAccMax = len(axes), 50.0, 1.0
    for c, a in enumerate(axes, 1):
        prm.profile[a - 1] = c
    assert gt.GT_SetCrdPrm(1, byref(prm)) == 0, gt.GTE_GetLastError()


def status() -> tuple[int, int]:
    run, seg = c_short(), c_int32()
    assert gt.GT_CrdStatus(1, byref(run), byref(seg)) == 0
    return run.value, seg.value


def remainder() -> int:
    n = c_long()
    assert gt.GT_GetRemainderSegNum(1, byref(n)) == 0, gt.GTE_GetLastError()
    return n.value


def prf(axis: int) -> float:
    p = c_double()
    assert gt.GT_GetPrfPos(axis, byref(p)) == 0
    return p.value


def gpo() -> int:
    v = c_long()
    assert gt.GT_GetDo(gt.MC_GPO, byref(v)) == 0
    return v.value


def test_outputs_and_dac_change_where_the_path_reaches_them():
    card()
    assert gt.GT_LnXYZ(1, 1000, 0, 0, 20.0, 0.5) == 0
    assert gt.GTN_BufDoBit(1, 1, gt.MC_GPO, 2, 1, 0) == 0
    assert gt.GT_BufDA(1, 4, 16000) == 0  # axis 4 is not in the system: a free output
    assert gt.GT_LnXYZG0(1, 1000, 1000, 500, 20.0, 0.5) == 0
    assert gt.GT_BufDoBit(1, gt.MC_GPO, 2, 0) == 0
    assert remainder() == 5 and gt.GT_CrdStart(1, 0) == 0
    dac = c_short()
    seen = []
    while status()[0]:
        gt.GTE_Wait(1)
        assert gt.GT_GetDac(4, byref(dac)) == 0
        seen.append((prf(1), prf(2), gpo() & 0b10, dac.value, remainder()))
    # the output is on exactly while the second (G0) line runs; the DAC set after line 1
    on = [s for s in seen if s[2]]
    assert on and all(s[0] == 1000.0 for s in on) and on[0][3] == 16000
    assert all(s[2] == 0 for s in seen if s[0] < 1000.0)
    assert seen[-1][:4] == (1000.0, 1000.0, 0, 16000) and remainder() == 0
    assert status() == (0, 5) and prf(3) == 500.0
    assert gt.GT_LnXYZAG0(1, 0, 0, 0, 0, 20.0, 0.5) == 7  # a 3-dimension system


def test_buffered_refusals():
    card()
    assert gt.GT_BufDoBit(1, gt.MC_ENABLE, 1, 1) == 7
    assert gt.GT_BufDoBit(1, gt.MC_GPO, 17, 1) == 7
    assert gt.GT_BufDA(1, 5, 100) == 7  # a 4-axis card
    assert gt.GT_BufLmtsOff(1, 9, -1) == 7
    assert gt.GT_BufDoBit(2, gt.MC_GPO, 1, 1) == 1  # crd 2 has no parameters
    assert gt.GT_SetCrdMapBase(1, 0) == 0
    base = c_short(5)
    assert gt.GT_GetCrdMapBase(1, byref(base)) == 0 and base.value == 0
    assert gt.GT_SetCrdMapBase(1, 8) == 1 and "not emulated" in gt.GTE_GetLastError()


def test_limits_off_for_a_move_onto_the_switch_and_on_again():
    """A path that ends on the positive limit switch of axis 1: with the switch watched the
    axis stops there with the limit flag (bit 5); with GT_BufLmtsOff before the line it
    reaches the end, and GT_BufLmtsOn after it watches the switch again."""
    machine = MachineDescription({1: AxisMachine(positive_limit=800.0)})
    card(axes=(1, 2), machine=machine)
    assert gt.GT_BufLmtsOff(1, 1, gt.MC_LIMIT_POSITIVE) == 0
    assert gt.GT_LnXY(1, 1000, 0, 20.0, 0.5) == 0
    assert gt.GT_BufLmtsOn(1, 1, gt.MC_LIMIT_POSITIVE) == 0
    assert gt.GT_CrdStart(1, 0) == 0
    while status()[0]:
        gt.GTE_Wait(1)
    sts = c_long()
    assert prf(1) == 1000.0 and status() == (0, 3)
    assert gt.GT_GetSts(1, byref(sts)) == 0 and sts.value & 1 << 5  # watched again: on it


def test_look_ahead_flush_with_crd_data_null():
    """The vendor examples' sequence: GT_InitLookAhead, the segments, GT_CrdData(crd, NULL,
    fifo) to push what the look-ahead holds, GT_CrdStart."""
    card(axes=(1, 2))
    buf = (gt.TCrdData * 200)()
    assert gt.GT_InitLookAhead(1, 0, 5.0, 1.0, 200, buf) == 0
    for k in range(1, 5):
        assert gt.GT_LnXY(1, 500 * k, 500 * (k % 2), 20.0, 0.5) == 0
    assert gt.GT_CrdData(1, None, 0) == 0 and remainder() == 4
    assert gt.GT_CrdStart(1, 0) == 0
    while status()[0]:
        gt.GTE_Wait(1)
    assert (prf(1), prf(2), status()) == (2000.0, 0.0, (0, 4))
    assert gt.GT_CrdData(1, byref(gt.TCrdData()), 0) == 1
    assert "not emulated" in gt.GTE_GetLastError()
    assert gt.GT_CrdData(1, None, 2) == 7
