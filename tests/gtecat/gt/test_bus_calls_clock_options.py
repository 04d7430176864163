"""GT_Open's clock options through the GT call: a bad one returns 7 (the manual's parameter
error) naming the option, its value and its range, with nothing on stderr and nothing
opened; a good one is the controller's clock."""

from __future__ import annotations

import math
from ctypes import byref, c_long, c_ulong

import pytest

from gtecat import gt
from gtecat.controller.clock_options import CALL_LATENCY_US_TEXT, CYCLE_MS_TEXT
from tests.conftest import EXAMPLES

from .conftest import bring_up

ENI = str(EXAMPLES / "manual_fig5_2.eni")

BAD = [("call_latency_us", v) for v in ("abc", None, -5, math.nan, 9.2e12, 2**70, True)] + [
    ("cycle_ms", v) for v in (0, -1, 6e-7, "1", math.inf, 1e9, 2**64, True)
]


@pytest.mark.parametrize(("name", "value"), BAD)
def test_a_bad_clock_option_is_refused_with_its_range(name, value, capfd):
    assert gt.GT_Open(eni=ENI, log="", **{name: value}) == 7
    err = gt.GTE_GetLastError()
    legal = CYCLE_MS_TEXT if name == "cycle_ms" else CALL_LATENCY_US_TEXT
    assert f"{name}=" in err and f"legal is {legal}" in err, err
    assert capfd.readouterr().err == ""  # no traceback
    s = c_long()
    assert gt.GT_GetSts(1, byref(s)) == -1  # nothing was opened
    assert gt.GT_Open(eni=ENI, log="") == 0, gt.GTE_GetLastError()  # and the next open works


def test_a_bad_option_of_another_card_is_refused_too():
    assert gt.GT_SetCardNo(1) == 0
    try:
        assert gt.GT_Open(eni=ENI, log="", cycle_ms=-1) == 7
        assert "cycle_ms=-1" in gt.GTE_GetLastError()
    finally:
        gt.GT_SetCardNo(0)


def test_good_clock_options_are_the_clock():
    """0.25 ms is kept over the ENI's 1 ms cycle; 1 ms of latency runs 4 cycles a call."""
    bring_up(cycle_ms=0.25, call_latency_us=1000)
    c = gt.GTE_Controller().clock
    assert (c.cycle_ns, c.call_latency_ns) == (250_000, 1_000_000)
    s, clk = c_long(), c_ulong()
    n = c.cycles
    assert gt.GT_GetSts(1, byref(s), 1, byref(clk)) == 0
    assert c.cycles - n in (4, 5)  # (the call's own latency; 5: one due from before)


def test_zero_latency_keeps_time_still_between_waits():
    """call_latency_us=0 in the auto clock: calls cost nothing, waits still let time pass."""
    assert gt.GT_Open(eni=ENI, log="", clock="auto", call_latency_us=0) == 0
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    c = gt.GTE_Controller().clock
    t = c.now_ns
    for _ in range(20):
        gt.GT_GetSts(1, byref(c_long()))
    assert c.now_ns == t
    gt.GTE_Wait(5)
    assert c.now_ns == t + 5_000_000
