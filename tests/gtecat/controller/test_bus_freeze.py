"""A large bus model is kept out of the cyclic collector's walks after GT_InitEcatComm
(gtecat/controller/core.py ``_freeze_bus``) and a closed one is collected at the next."""

from __future__ import annotations

import gc
import weakref
from ctypes import byref, c_short
from pathlib import Path

from gtecat import gt
from gtecat.controller import core
from tools.gen_axes_eni import write_axes_eni


def _up(eni: Path) -> weakref.ref[object]:
    assert gt.GT_Open(eni=str(eni), clock="lockstep", log="") == 0
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    ready = c_short()
    for _ in range(100):
        if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
            break
        gt.GTE_Wait(1)
    assert ready.value == 1
    return weakref.ref(gt.GTE_Controller().master)


def test_a_large_bus_is_frozen_and_a_closed_one_collected_at_the_next(
    tmp_path: Path, monkeypatch
) -> None:
    if gc.get_freeze_count():  # a process that froze objects itself is left as it is
        gc.unfreeze()
    monkeypatch.setattr(core, "FREEZE_MIN_SLAVES", 4)  # "large" from 4 slaves: a quick bus
    eni = write_axes_eni(core.FREEZE_MIN_SLAVES, tmp_path / "bus.eni")
    try:
        first = _up(eni)
        assert gc.get_freeze_count() > 0 and core._FROZEN[0]
        gt.GT_Close()
        second = _up(eni)
        assert first() is None and second() is not None  # the closed bus was collected
        assert gc.get_freeze_count() > 0
        gt.GT_Close()
    finally:
        core._thaw_bus()
    assert gc.get_freeze_count() == 0 and not core._FROZEN[0]


def test_a_small_bus_is_not_frozen(tmp_path: Path) -> None:
    core._thaw_bus()
    _up(write_axes_eni(2, tmp_path / "bus.eni"))
    try:
        assert not core._FROZEN[0]
    finally:
        gt.GT_Close()


def test_the_gt_imports_own_freeze_leaves_a_large_bus_frozen_and_a_processs_own_not(
    tmp_path: Path, monkeypatch
) -> None:
    """gtecat.gt's import freezes what it made (core.freeze_import): that is not a freeze of
    the process's own, so a large bus is frozen after its bring-up still; objects the
    process froze before the import leave the bus as it is."""
    core._thaw_bus()
    gc.unfreeze()  # (as a process that has frozen nothing yet)
    monkeypatch.setattr(core, "_IMPORT_FROZEN", [0])
    monkeypatch.setattr(core, "FREEZE_MIN_SLAVES", 4)
    eni = write_axes_eni(core.FREEZE_MIN_SLAVES, tmp_path / "bus.eni")
    try:
        core.freeze_import()
        assert gc.get_freeze_count() > 0
        _up(eni)
        assert core._FROZEN[0]
        gt.GT_Close()
        core._thaw_bus()
        assert gc.get_freeze_count() == 0
        gc.freeze()  # the process's own
        core.freeze_import()
        _up(eni)
        assert not core._FROZEN[0]
    finally:
        gt.GT_Close()
        core._thaw_bus()
        gc.unfreeze()
