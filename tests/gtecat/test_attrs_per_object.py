"""A closed controller is freed: the state other modules keep per controller, per axis and
per axis's resources (gtecat._attrs.PerObject: capture, smart and drive homing, the older
cards' homing, digital IO, servo loop, triggers, PVT tables, ...) lives on the object it
belongs to, so it never keeps its owner alive.  An application that opens and closes the
controller again and again (a test harness, an HMI that brings the bus up anew) does not
grow."""

from __future__ import annotations

import gc
import weakref
from ctypes import byref, c_double, c_long, c_short
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.gt import _core
from tests.gtecat.gt.conftest import bring_up


@pytest.fixture(autouse=True)
def _closed_controller():
    _core.close_all()
    yield
    _core.close_all()


def _use_every_kind_of_state(cfg: str) -> None:
    """GT calls that make each kind of per-controller state (their codes do not matter)."""
    st, v = c_short(), c_long()
    gt.GT_LoadConfig(cfg)
    gt.GT_AxisOn(1)
    gt.GT_SetHomingMode(1, 6)
    gt.GT_SetEcatHomingPrm(1, 34, 10.0, 5.0, 1.0, 0, 0)
    gt.GT_StartEcatHoming(1)
    gt.GT_GetEcatHomingStatus(1, byref(st))
    gt.GT_SetCaptureMode(2, gt.CAPTURE_HOME)
    gt.GT_GetCaptureStatus(2, byref(st), byref(v), 1, None)
    gt.GT_Home(2, 20000, 10.0, 1.0, 0)
    gt.GT_GetHomeStatus(2, byref(gt.THomeStatus()))
    gt.GT_GetDi(gt.MC_GPI, byref(v))
    gt.GT_SetDoBit(gt.MC_GPO, 1, 1)
    gt.GT_SetPid(1, 1, byref(gt.TPid(kp=0.5, limit=100)))
    gt.GT_OpenExtMdl(None)
    mode = gt.TPosCompareMode(mode=gt.POS_COMPARE_MODE_FIFO, dimension=1, sourceMode=1, sourceX=3)
    gt.GT_SetPosCompareMode(1, 1, byref(mode))
    t, p, vel = (c_double * 2)(0, 100), (c_double * 2)(0, 1000), (c_double * 2)(0, 0)
    gt.GT_PvtTable(1, 2, t, p, vel)
    comp = (c_long * 2)(0, 1)
    gt.GT_SetLeadScrewComp(1, 2, 0, 1000, comp, comp)
    gt.GT_EnableLeadScrewComp(1, 1)
    gt.GT_ClearTriggerStatus(1)
    gt.GT_GetGantryMode(1, byref(st), byref(st), byref(st), byref(v))


def test_a_closed_controller_and_its_master_are_freed(tmp_path: Path) -> None:
    cfg = tmp_path / "axis.cfg"
    cfg.write_text("[axis 1]\nactive = 1\n")
    refs = []
    for _ in range(2):  # (a second one: the first one's state is not kept by the next)
        bring_up(clock="lockstep")
        ctl = _core.SESSION.controllers[1]
        refs.append((weakref.ref(ctl), weakref.ref(ctl.master)))
        _use_every_kind_of_state(str(cfg))
        del ctl
        assert gt.GT_Close() == 0
    gc.collect()
    alive = [(c() is not None, m() is not None) for c, m in refs]
    assert alive == [(False, False)] * 2
