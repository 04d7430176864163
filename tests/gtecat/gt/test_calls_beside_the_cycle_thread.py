"""GT calls while the realtime clock's thread runs cycles: a call that gives axes back from
the axis bank does it holding the cycle lock, as the call itself runs, so that no cycle
steps the bank half way through a release (its objects would miss that cycle or get it
twice).  A realtime test: it waits on the wall clock, with a bounded deadline."""

from __future__ import annotations

import time
from ctypes import byref, c_double, c_short

from gtecat import gt
from tests.conftest import EXAMPLES


def _wait(pred, what: str, timeout: float = 10.0) -> None:
    deadline = time.monotonic() + timeout
    while not pred():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.005)


def test_a_release_from_the_bank_holds_the_cycle_lock():
    assert gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), clock="realtime", log="") == 0
    try:
        assert gt.GT_InitEcatComm() == 0
        ready = c_short()
        _wait(lambda: gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1, "the bus")
        assert gt.GT_StartEcatComm() == 0
        ctl = gt.GTE_Controller()
        assert ctl.clock._thread is not None and ctl.bank is not None
        for a in (1, 2):
            assert gt.GT_AxisOn(a) == 0
            assert gt.GT_PrfTrap(a) == 0
            assert gt.GT_SetVel(a, 5) == 0
            assert gt.GT_SetPos(a, 10_000_000) == 0
        assert gt.GT_Update(0b11) == 0
        _wait(lambda: ctl.bank.n_alive == 2, "both axes in the bank")

        held: list[bool] = []
        bank = ctl.bank
        before, in_place = bank.before_call, bank.call_in_place

        def spy(*args):
            held.append(ctl.clock.lock._is_owned())
            return before(*args)

        def spy_in_place(*args):  # (a Trap move's start runs on its row in place)
            held.append(ctl.clock.lock._is_owned())
            return in_place(*args)

        bank.before_call, bank.call_in_place = spy, spy_in_place
        for _ in range(20):
            assert gt.GT_SetVel(1, 6) == 0  # names axis 1: it goes back first, or in place
            assert gt.GT_Update(1) == 0
            assert gt.GT_SetSoftLimit(1, 2**30, -(2**30)) == 0  # names axis 1: it goes back
            pos = c_double()
            assert gt.GT_GetPrfPos(2, byref(pos)) == 0
            time.sleep(0.002)
        assert held and all(held), held
    finally:
        gt.GT_Close()
