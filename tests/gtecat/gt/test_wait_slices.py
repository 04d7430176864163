"""GTE_Wait runs long waits in slices (gtecat/controller/core.py Controller.wait_ms): the
same cycles as one advance, with a hook between slices that a server uses to serve its
other clients, and where a KeyboardInterrupt (Ctrl-C) stops the wait."""

from __future__ import annotations

from ctypes import byref, c_ulong

import pytest

from gtecat import gt
from tests.gtecat.gt.conftest import bring_up


def _clock() -> int:
    c = c_ulong()
    assert gt.GT_GetClock(byref(c)) == 0
    return c.value


def test_a_long_wait_runs_in_slices_and_ends_on_time(monkeypatch):
    bring_up(clock="lockstep")
    ctl = gt.GTE_Controller()
    monkeypatch.setattr(type(ctl), "WAIT_SLICE_NS", 20_000_000)
    seen = []
    ctl.slice_hook = lambda: seen.append(ctl.clock.now_ns)
    t0, cycles0 = _clock(), ctl.clock.cycles
    assert gt.GTE_Wait(95) == 0
    assert _clock() - t0 == 95 and ctl.clock.cycles - cycles0 == 95
    assert len(seen) == 4  # after 20, 40, 60, 80 ms; none after the last slice
    # a hook's own calls are controller time too: the wait still ends at its end time
    ctl.slice_hook = lambda: ctl.clock.advance_ns(5_000_000)
    t0 = _clock()
    assert gt.GTE_Wait(95) == 0 and _clock() - t0 == 95


def test_ctrl_c_between_slices_reaches_the_caller(monkeypatch):
    bring_up(clock="lockstep")
    ctl = gt.GTE_Controller()
    monkeypatch.setattr(type(ctl), "WAIT_SLICE_NS", 10_000_000)

    def interrupt() -> None:
        raise KeyboardInterrupt

    ctl.slice_hook = interrupt
    t0 = _clock()
    with pytest.raises(KeyboardInterrupt):
        gt.GTE_Wait(86_400_000)  # a day: stopped after the first slice
    assert _clock() - t0 == 10
    ctl.slice_hook = None
    assert gt.GTE_Wait(1) == 0  # the controller goes on
