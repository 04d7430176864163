"""The GT-400 library's current-axis calls as a GT-400 application makes them (vendor ``gt400.h``;
the S-curve sequence ``GT_PrflS``, ``GT_SetJerk``, ``GT_SetMAcc``, ``GT_SetVel``,
``GT_SetPos``, ``GT_Update`` and the wait ``(sts & 0x1) || !(sts & 0x400)`` are those of
field code), checked against closed forms and from the GT layer."""

from __future__ import annotations

import math
from ctypes import byref, c_double, c_long, c_ushort

import pytest

from gtecat import gt
from gtecat.compat import gt400 as g
from gtecat.compat import last_error

from .conftest import open_card


@pytest.fixture(autouse=True)
def _released():
    yield
    if g._CARD[0] is not None:
        g._CARD[0].close()
    g._CARD[0] = None


def sts() -> int:
    s = c_ushort()
    assert g.GT_GetSts(byref(s)) == 0
    return s.value


def wait_done(limit_ms: int = 20_000) -> int:
    for ms in range(limit_ms):
        gt.GTE_Wait(1)
        s = sts()
        if (s & 0x1) or not (s & 0x400):
            return ms + 1
    raise AssertionError("the motion never ended")


def prf() -> tuple[int, float]:
    p, v = c_long(), c_double()
    assert g.GT_GetPrfPos(byref(p)) == 0 and g.GT_GetPrfVel(byref(v)) == 0
    return p.value, v.value


def test_s_curve_move_of_the_current_axis():
    open_card(a2={"positive_limit": 1e9})
    assert g.GT_Open() == 0  # uses the card the test opened
    assert g.GT_Axis(2) == 0 and g.GT_AxisOn() == 0 and g.GT_ClrSts() == 0
    for call in (g.GT_PrflS(), g.GT_SetJerk(0.002), g.GT_SetMAcc(0.04), g.GT_SetVel(4)):
        assert call == 0
    assert g.GT_SetPos(1200) == 0 and g.GT_Update() == 0
    ms = wait_done()
    # jerk-limited ramps of 120 ms (20 ms of jerk at each end), then the cruise at 4 pulse/ms
    t_ramp = 4 / 0.04 + 0.04 / 0.002
    assert abs(ms - (t_ramp + 1200 / 4)) <= 2
    assert prf() == (1200, 0.0) and sts() & 0x1
    assert g.GT_ClrSts() == 0 and not sts() & 0x1
    p = c_double()
    assert gt.GT_GetPrfPos(2, byref(p)) == 0 and p.value == 1200.0  # the GT layer agrees
    assert gt.GT_GetPrfPos(1, byref(p)) == 0 and p.value == 0.0  # axis 1 never moved


def test_trapezoid_velocity_mode_and_the_two_stops():
    open_card()
    assert g.GT_Open() == 0 and g.GT_AxisOn() == 0  # current axis 1
    assert g.GT_PrflT() == 0 and g.GT_SetAcc(0.1) == 0 and g.GT_SetVel(5) == 0
    assert g.GT_SetPos(-1000) == 0 and g.GT_Update() == 0
    ms = wait_done()
    assert abs(ms - (1000 / 5 + 5 / 0.1)) <= 2 and prf()[0] == -1000
    assert g.GT_PrflV() == 0 and g.GT_SetVel(-2) == 0 and g.GT_Update() == 0
    gt.GTE_Wait(100)
    assert prf()[1] == -2.0 and sts() & 0x400
    assert g.GT_SetVel(-3) == 0 and g.GT_Update() == 0  # a new speed on the fly
    gt.GTE_Wait(100)
    assert prf()[1] == -3.0
    assert g.GT_SetVel(3) == 0 and g.GT_Update() == 1  # not the other way round
    assert g.GT_PrflT() == 1  # no profile change while moving
    assert g.GT_SmthStp() == 0
    gt.GTE_Wait(29)
    assert prf()[1] != 0.0  # decelerating with acc 0.1: 30 ms from 3 pulse/ms
    gt.GTE_Wait(5)
    assert prf()[1] == 0.0 and sts() & 0x1
    assert g.GT_SetVel(-2) == 0 and g.GT_Update() == 0
    gt.GTE_Wait(50)
    assert g.GT_AbptStp() == 0
    gt.GTE_Wait(2)
    assert prf()[1] == 0.0


def test_limits_and_refusals():
    open_card(a1={"positive_limit": 500.0})
    assert g.GT_Open() == 0 and g.GT_AxisOn() == 0
    assert g.GT_SetVel(10) == 0 and g.GT_SetAcc(1) == 0 and g.GT_SetPos(2000) == 0
    assert g.GT_Update() == 0
    wait_done()
    assert sts() & 0x20 and math.isclose(prf()[0], 500, abs_tol=60)
    assert g.GT_Update() == 1  # on the positive limit: no move that way
    assert g.GT_Axis(5) == 7 and "1..4" in last_error()
    assert g.GT_SetAcc(0) == 7 and g.GT_ExOptBit(16, 0) == 7


def test_general_io_is_active_low():
    open_card()
    assert g.GT_Open() == 0
    s = c_ushort()
    assert g.GT_ExInpt(byref(s)) == 0 and s.value == 0xFFFF  # nothing active
    assert gt.GTE_SetGpi(3, 1) == 0  # EXI2 active
    assert g.GT_ExInpt(byref(s)) == 0 and s.value == 0xFFFB
    assert g.GT_ExOptBit(4, 0) == 0  # EXO4 on
    do = c_long()
    assert gt.GT_GetDo(gt.MC_GPO, byref(do)) == 0 and do.value == 1 << 4
    assert g.GT_ExOpt(0xFF00) == 0 and gt.GT_GetDo(gt.MC_GPO, byref(do)) == 0
    assert do.value == 0x00FF
    assert g.GT_GetExOpt(byref(s)) == 0 and s.value == 0xFF00


def test_calls_before_open_return_1():
    assert g.GT_Axis(1) == 1
    assert "GT_Open first" in last_error()
