"""The realtime clock (DESIGN.md "Time"): a cycle thread against the wall clock.

The only tests that wait on the wall clock; every wait is bounded.
"""

from __future__ import annotations

import time
from ctypes import byref, c_short, c_ulong, c_ushort

from gtecat import gt
from tests.conftest import EXAMPLES


def test_realtime_bus_runs_by_itself():
    gt.GT_Close()
    try:
        assert gt.GT_Open(eni=str(EXAMPLES / "manual_fig5_2.eni"), clock="realtime", log="") == 0
        assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
        st = c_short()
        deadline = time.monotonic() + 5.0
        while time.monotonic() < deadline:
            if gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1:
                break
            time.sleep(0.005)
        assert st.value == 1, gt.GTE_GetLastError()
        io = gt.GTE_Slave(2)
        io.wire(0, 0)
        assert gt.GT_SetEcatRawData(32, 1, byref(c_ushort(1))) == 0
        t0 = c_ulong()
        gt.GT_GetClock(byref(t0))
        assert gt.GTE_Wait(30) == 0  # sleeps with the cycle lock released
        t1 = c_ulong()
        gt.GT_GetClock(byref(t1))
        # the bus runs by itself: controller time goes on without calls (a loaded machine may
        # hold the cycle thread back a while, so wait for it, within a bounded wall time)
        deadline = time.monotonic() + 3.0
        while t1.value - t0.value < 20 and time.monotonic() < deadline:
            time.sleep(0.01)
            gt.GT_GetClock(byref(t1))
        assert t1.value - t0.value >= 20
        back = c_ushort()
        assert gt.GT_GetEcatRawData(34, 1, byref(back)) == 0
        assert back.value & 1 == 1
        assert gt.GTE_Controller().clock.stats.cycles > 10
    finally:
        gt.GT_Close()
