"""GT_ClrSts (manual entry 8) polled by an error handler while the axis bank runs the axes.

An axis the bank runs with no flag latched and no link alarm has nothing to clear: the call
leaves it in the bank (touching it would give it back, and the bank would claim it again at
its next cycle).  A drive fault (an overcurrent, 2310h) still gets its reset, and the session
reads exactly as with the bank off.
"""

from __future__ import annotations

from ctypes import c_double, c_long

import pytest

from gtecat import faults, gt
from gtecat.controller.axis import Axis
from tests.conftest import EXAMPLES


@pytest.fixture(autouse=True)
def _closed():
    gt.GT_Close()
    yield
    gt.GT_Close()


def _session(bank: str) -> tuple[list[tuple], int]:
    """Twelve axes in Trap moves, GT_ClrSts(1, 12) every 5 ms, axis 3's drive faulted at
    100 ms for 50 ms: GT_GetSts and the positions of every axis after each call, and after
    how many of the calls axis 1 was still in the bank."""
    opts = dict(clock="lockstep", log="", bank=bank)
    assert gt.GT_Open(eni=str(EXAMPLES / "twelve_axes.eni"), **opts) == 0
    assert gt.GT_InitEcatComm() == 0
    gt.GTE_Wait(300)
    assert gt.GT_StartEcatComm() == 0
    for a in range(1, 13):
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(20)
    for a in range(1, 13):
        assert gt.GT_PrfTrap(a) == 0
        assert gt.GT_SetVel(a, 2 + a % 3) == 0
        assert gt.GT_SetPos(a, 2_000 * a) == 0
    assert gt.GT_Update(0xFFF) == 0
    faults.inject("drive_fault", axis=3, code=0x2310, after_ms=100, duration_ms=50)
    ctl = gt.GTE_Controller()
    seen, banked = [], 0
    sts = (c_long * 12)()
    pos = (c_double * 12)()
    for _ in range(80):
        gt.GTE_Wait(5)
        rc = gt.GT_ClrSts(1, 12)
        banked += type(ctl.axes[1]) is not Axis
        assert gt.GT_GetSts(1, sts, 12, None) == 0
        assert gt.GT_GetPrfPos(1, pos, 12, None) == 0
        seen.append((rc, tuple(sts), tuple(pos)))
        if sts[2] & 0x200 == 0 and not seen[-1][1][2] & 0x2:  # axis 3 off and no alarm: on
            gt.GT_AxisOn(3)
    gt.GT_Close()
    return seen, banked


def test_gt_clrsts_leaves_the_bank_s_axes_with_nothing_to_clear_and_reads_as_without_it():
    with_bank, banked = _session("auto")
    without, never = _session("off")
    assert never == 0
    assert banked > 60, "axis 1 stayed in the bank across the error handler's GT_ClrSts"
    assert with_bank == without
    alarms = [s[2] & 0x2 for _, s, _ in with_bank]
    assert any(alarms) and not alarms[-1]  # axis 3's fault was seen, then reset
