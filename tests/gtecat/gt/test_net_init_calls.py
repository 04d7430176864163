"""A GSN-E application's bring-up as its own code does it: ``GTN_OpenCard(CHANNEL_PCIE, NULL,
NULL)``, ``GTN_NetInit(mode, "Gecat.xml", overTime, &status)``, then motion; and the
ring-net absolute encoder read as a 64-bit count."""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_longlong

from gtecat import gt
from tests.conftest import EXAMPLES

CHANNEL_PCIE = 5


def test_open_card_net_init_and_the_absolute_encoder(tmp_path):
    eni = str(EXAMPLES / "manual_fig5_2.eni")
    assert gt.GTN_OpenCard(CHANNEL_PCIE, None, None, eni=eni, clock="lockstep", log="") == 0
    status = c_long(-1)
    assert gt.GTN_NetInit(2, b"Gecat.xml", 0, byref(status)) == 0, gt.GTE_GetLastError()
    assert status.value == 1
    assert gt.GTN_AxisOn(1, 1) == 0 and gt.GTN_PrfTrap(1, 1) == 0
    assert gt.GTN_SetTrapPrm(1, 1, byref(gt.TTrapPrm(acc=1, dec=1))) == 0
    assert gt.GTN_SetPos(1, 1, 5000) == 0 and gt.GTN_SetVel(1, 1, 20.0) == 0
    assert gt.GTN_Update(1, 1) == 0
    gt.GTE_Wait(600)
    pos, enc = c_longlong(), c_double()
    assert gt.GTN_RN_GetAbsEncPosEx(1, 1, byref(pos)) == 0
    assert gt.GTN_GetEncPos(1, 1, byref(enc)) == 0 and pos.value == round(enc.value) == 5000
    assert gt.GTN_RN_GetAbsEncPosEx(1, 99, byref(pos)) == 7
    assert gt.GTN_NetInit(0, None, -1, byref(status)) == 7
    gt.GT_Close()
    missing = str(tmp_path / "none.eni")
    assert gt.GTN_OpenCard(CHANNEL_PCIE, eni=missing, clock="lockstep", log="") == 0
    assert gt.GTN_NetInit(0, None, 1, byref(status)) == 11902 and status.value == 0
    assert "network" in gt.GTE_GetLastError()
