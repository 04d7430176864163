"""GT-level tests: each test opens the controller and always closes it."""

from __future__ import annotations

from ctypes import byref, c_short

import pytest

from gtecat import gt
from gtecat.gt import _core
from tests.conftest import EXAMPLES


@pytest.fixture(autouse=True)
def _closed_controller():
    _core.close_all()
    yield
    _core.close_all()


def bring_up(eni: str = "manual_fig5_2.eni", **options) -> None:
    """Manual example 5-5 in Python: open, init, wait ready, start."""
    options.setdefault("log", "")
    assert gt.GT_Open(eni=str(EXAMPLES / eni), **options) == 0, gt.GTE_GetLastError()
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    status = c_short()
    for _ in range(10_000):
        rc = gt.GT_IsEcatReady(byref(status))
        if rc == 0 and status.value == 1:
            break
        if options.get("clock") == "lockstep":
            gt.GTE_Wait(1)  # nothing moves in lockstep until the test lets time pass
    else:
        raise AssertionError("bus never ready: " + gt.GTE_GetLastError())
    assert gt.GT_StartEcatComm() == 0, gt.GTE_GetLastError()


def trap_move(ax: int, pos: int, vel: float) -> None:
    """Axis ``ax`` to ``pos`` in Trap at ``vel`` (acc 0.3, dec 0.2), started."""
    assert gt.GT_PrfTrap(ax) == 0
    p = gt.TTrapPrm()
    p.acc, p.dec = 0.3, 0.2
    assert gt.GT_SetTrapPrm(ax, byref(p)) == 0
    assert gt.GT_SetVel(ax, vel) == 0
    assert gt.GT_SetPos(ax, pos) == 0
    assert gt.GT_Update(1 << (ax - 1)) == 0
