"""The readers of several values polled in loops - GT_GetCaptureStatus (a capture armed by
GT_SetCaptureMode, manual chapter 13 "capture") and GT_CrdStatus (a coordinate system's run
flag and finished segments, chapter 10) - answer through their C entries as the table path
does, poll by poll, while the axis bank runs the axes; every other shape is the table's."""

from __future__ import annotations

import ctypes
from ctypes import byref, c_long, c_short
from typing import Any

import pytest

from gtecat import gt
from gtecat.controller.epoch import EPOCH
from gtecat.drives.machine import AxisMachine, MachineDescription
from gtecat.gt import centry

from .conftest import bring_up

pytestmark = pytest.mark.skipif(bool(centry.REASON), reason=f"no C entry: {centry.REASON}")
HOME_LO, HOME_HI = 20_000, 30_000


def _both(fn: Any, *args: Any) -> tuple[Any, Any]:
    """(code, values) through the public function, then through the table path."""
    out = []
    for call in (fn, fn.slow):
        vals = [type(a)() if isinstance(a, ctypes._SimpleCData) else a for a in args]
        ptrs = [byref(v) if isinstance(v, ctypes._SimpleCData) else v for v in vals]
        rc = call(*ptrs)
        out.append((rc, [v.value for v in vals if isinstance(v, ctypes._SimpleCData)]))
    return out[0], out[1]


def _answered_in_c(fn: Any, *args: Any) -> bool:
    """The call answered without the table path (whose every call makes the epoch grow)."""
    before = EPOCH.n
    return fn(*args) == 0 and EPOCH.n == before


def test_a_home_capture_polled_while_the_axis_moves_answers_as_the_table() -> None:
    m = MachineDescription({1: AxisMachine(home_switch=((HOME_LO, HOME_HI),))})
    bring_up("manual_fig5_2.eni", machine=m, clock="lockstep")
    try:
        _up()
        ctl = gt.GTE_Controller()
        st, val = c_short(), c_long()
        assert gt.GT_GetCaptureStatus(1, byref(st), byref(val)) == 0  # (the unit made)
        assert gt.GT_SetCaptureMode(1, gt.CAPTURE_HOME) == 0
        assert gt.GT_PrfTrap(1) == 0
        assert gt.GT_SetTrapPrm(1, byref(gt.TTrapPrm(acc=0.5, dec=0.5))) == 0
        assert gt.GT_SetVel(1, 20) == 0 and gt.GT_SetPos(1, 50_000) == 0
        assert gt.GT_Update(1) == 0
        banked = captured = 0
        for _ in range(400):
            gt.GTE_Wait(7)
            banked += ctl.resources[1].bank is not None
            a, b = _both(gt.GT_GetCaptureStatus, 1, c_short(), c_long())
            assert a == b
            a, b = _both(gt.GT_GetCaptureStatus, 1, c_short(), c_long(), 1, None)
            assert a == b
            if a[1][0] == 1:
                captured += 1
                assert HOME_LO - 50 <= a[1][1] <= HOME_LO + 50, a
        assert captured and banked, (captured, banked)
        assert _answered_in_c(gt.GT_GetCaptureStatus, 1, byref(st), byref(val))
        assert _answered_in_c(gt.GT_GetCaptureStatus, 1, st, val, 1, 0)
        assert gt.GT_ClearCaptureStatus(1) == 0
        assert _both(gt.GT_GetCaptureStatus, 1, c_short(), c_long())[0][1][0] == 0
        # shapes the entry leaves to the table: count 2, a clock, an axis past the bus
        for args in ((1, c_short(), c_long(), 2), (9, c_short(), c_long())):
            a, b = _both(gt.GT_GetCaptureStatus, *args)
            assert a == b
        clk = ctypes.c_ulong()
        assert gt.GT_GetCaptureStatus(1, byref(st), byref(val), 1, byref(clk)) == 0
        assert clk.value == ctl.clock_ms() & 0xFFFFFFFF
    finally:
        gt.GT_Close()


def test_a_coordinate_system_polled_while_it_runs_answers_as_the_table() -> None:
    bring_up("manual_fig5_2.eni", clock="lockstep")
    try:
        _up()
        prm = gt.TCrdPrm()
        prm.dimension = 2
        prm.profile[0], prm.profile[1] = 1, 2
        prm.synVelMax, prm.synAccMax = 100.0, 2.0
        a, b = _both(gt.GT_CrdStatus, 1, c_short(), c_long(), 0)  # (no parameters yet)
        assert a == b and a[0] != 0
        assert gt.GT_SetCrdPrm(1, byref(prm)) == 0, gt.GTE_GetLastError()
        assert gt.GT_CrdClear(1, 0) == 0
        for k in range(1, 5):
            assert gt.GT_LnXY(1, 4000 * k, 3000 * (k % 2), 20.0, 0.5) == 0
        assert gt.GT_CrdStart(1, 0) == 0
        runs = set()
        shapes = [
            (1, c_short(), c_long(), 0),
            (1, c_short(), c_long()),
            (1, c_short(), c_long(), 1),
        ]
        for _ in range(300):
            gt.GTE_Wait(5)
            for k, args in enumerate(shapes):
                a, b = _both(gt.GT_CrdStatus, *args)
                assert a == b, args
                if k == 0:
                    runs.add(tuple(a[1]))
        assert any(r[0] == 1 for r in runs), runs  # (seen running)
        assert (0, 4) in runs, runs  # (and done, its four segments finished)
        r, seg = c_short(), c_long()
        assert _answered_in_c(gt.GT_CrdStatus, 1, byref(r), byref(seg))
        assert _answered_in_c(gt.GT_CrdStatus, 1, r, seg, 0)
    finally:
        gt.GT_Close()


def _up() -> None:
    for a in (1, 2):
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(10)
