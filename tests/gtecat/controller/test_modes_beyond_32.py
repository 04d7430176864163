"""PT, Gear, Follow and coordinated motion on a bus of more than 32 axes (lockstep clock).

Axis 32 is bit 31 of a ``long`` mask: the starts take it whether the caller passes the
negative ``long`` or the unsigned word.  Each core has its own two coordinate systems:
``GTN_SetCrdPrm(2, 1, ...)`` sets up system 1 of core 2 over that core's profiles, and
neither core's system reaches the other's.
"""

from __future__ import annotations

from collections.abc import Iterator
from ctypes import byref, c_double, c_int32, c_long, c_short
from pathlib import Path

import pytest

from gtecat import gt
from tools.gen_axes_eni import write_axes_eni

AXES = 34
MOVING = 1 << 10


@pytest.fixture(scope="module")
def bus(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    eni = write_axes_eni(AXES, Path(tmp_path_factory.mktemp("eni")) / "axes34.eni")
    gt.GT_Close()
    assert gt.GT_Open(eni=str(eni), clock="lockstep", log="") == 0, gt.GTE_GetLastError()
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    ready = c_short()
    for _ in range(1000):
        if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
            break
        gt.GTE_Wait(1)
    assert gt.GT_StartEcatComm() == 0, gt.GTE_GetLastError()
    for a in range(1, AXES + 1):
        core, local = (a - 1) // 32 + 1, (a - 1) % 32 + 1
        assert gt.GTN_AxisOn(core, local) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(5)
    yield
    gt.GT_Close()


def moving(axis: int) -> bool:
    s = c_long()
    assert gt.GT_GetSts(axis, byref(s)) == 0, gt.GTE_GetLastError()
    return bool(s.value & MOVING)


def drop(*axes: int) -> None:
    """Servo off and on again: the motion is dropped (GT_Stop's mask reaches axes 1-12)."""
    for a in axes:
        assert gt.GT_AxisOff(a) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(5)
    for a in axes:
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(5)
    assert not any(moving(a) for a in axes)


@pytest.mark.parametrize("mask", [-(1 << 31), 1 << 31], ids=["long", "unsigned"])
def test_pt_start_takes_axis_32(bus: None, mask: int) -> None:
    assert gt.GT_PrfPt(32, gt.PT_MODE_STATIC) == 0, gt.GTE_GetLastError()
    assert gt.GT_PtClear(32, 0) == 0
    assert gt.GT_PtClear(32, 1) == 0
    for fifo in (0, 1):
        for k in (1, 2):
            assert gt.GT_PtData(32, 100.0 * k, 10 * k, gt.PT_SEGMENT_NORMAL, fifo) == 0
    assert gt.GT_PtStart(mask, mask) == 0, gt.GTE_GetLastError()  # option: FIFO2 for axis 32
    assert gt.GT_PtStart(mask, 0) == 1  # moving already
    drop(32)
    p = c_double()
    assert gt.GT_GetPrfPos(32, byref(p)) == 0
    start = p.value
    assert gt.GT_PtStart(mask, 0) == 0, gt.GTE_GetLastError()  # FIFO1 holds the data
    gt.GTE_Wait(2)
    assert moving(32)
    gt.GTE_Wait(30)
    assert not moving(32)
    assert gt.GT_GetPrfPos(32, byref(p)) == 0 and p.value == start + 200.0


def test_gear_and_follow_start_take_axis_32(bus: None) -> None:
    trap = gt.TTrapPrm()
    trap.acc, trap.dec, trap.smoothTime = 0.5, 0.5, 0
    assert gt.GT_PrfTrap(31) == 0 and gt.GT_SetTrapPrm(31, byref(trap)) == 0
    assert gt.GT_SetPos(31, 10_000_000) == 0 and gt.GT_SetVel(31, 10) == 0
    assert gt.GT_Update(1 << 30) == 0, gt.GTE_GetLastError()
    assert gt.GT_PrfGear(32, 0) == 0
    assert gt.GT_SetGearMaster(32, 31, gt.GEAR_MASTER_PROFILE, 0) == 0
    assert gt.GT_SetGearRatio(32, 2, 1, 0) == 0
    assert gt.GT_GearStart(-(1 << 31)) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(10)
    assert moving(32)
    drop(32)
    assert gt.GT_PrfFollow(32, 0) == 0
    assert gt.GT_SetFollowMaster(32, 31, gt.FOLLOW_MASTER_PROFILE, 0) == 0
    assert gt.GT_FollowData(32, 1000, 500.0, gt.FOLLOW_SEGMENT_NORMAL, 1) == 0
    assert gt.GT_FollowStart(1 << 31, 1 << 31) == 0, gt.GTE_GetLastError()  # FIFO2
    gt.GTE_Wait(10)
    assert moving(32)
    drop(31, 32)


def crd_status(core: int, crd: int) -> tuple[int, int]:
    run, seg = c_short(), c_int32()
    assert gt.GTN_CrdStatus(core, crd, byref(run), byref(seg), 0) == 0, gt.GTE_GetLastError()
    return run.value, seg.value


@pytest.mark.long
def test_each_core_has_its_own_coordinate_systems(bus: None) -> None:
    for core in (1, 2):
        prm = gt.TCrdPrm()
        prm.dimension = 2
        prm.profile[0], prm.profile[1] = 1, 2  # the core's local axes 1 and 2
        prm.synVelMax, prm.synAccMax = 100.0, 2.0
        assert gt.GTN_SetCrdPrm(core, 1, byref(prm)) == 0, gt.GTE_GetLastError()
        assert gt.GTN_CrdClear(core, 1, 0) == 0
        x = 1000 * core
        assert gt.GTN_LnXY(core, 1, x, x, 20.0, 0.5, 0.0, 0) == 0, gt.GTE_GetLastError()
    assert gt.GTN_CrdStart(1, 1, 0) == 0, gt.GTE_GetLastError()
    assert gt.GTN_CrdStart(2, 1, 0) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(5)
    assert crd_status(1, 1)[0] == 1 and crd_status(2, 1)[0] == 1
    assert all(moving(a) for a in (1, 2, 33, 34)) and not moving(3)
    assert gt.GTN_Stop(2, 1 << 12, 1 << 12) == 0  # core 2's system 1, abruptly
    gt.GTE_Wait(30)
    assert crd_status(2, 1)[0] == 0 and crd_status(1, 1)[0] == 1
    assert moving(1) and not moving(33)
    gt.GTE_Wait(100)
    assert crd_status(1, 1) == (0, 1)
    p = c_double()
    for a, target in ((1, 1000.0), (2, 1000.0)):
        assert gt.GT_GetPrfPos(a, byref(p)) == 0 and p.value == pytest.approx(target, abs=1e-6)
    assert gt.GT_GetPrfPos(33, byref(p)) == 0 and 0.0 < p.value < 2000.0
