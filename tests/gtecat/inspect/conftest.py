"""A private runtime folder for every test of the inspection endpoints (never the user's)."""

from __future__ import annotations

import ctypes
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
FIG5_2 = ROOT / "gtecat" / "examples" / "manual_fig5_2.eni"


@pytest.fixture
def runtime_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    run = tmp_path / "run"
    run.mkdir(mode=0o700)
    monkeypatch.setenv("XDG_RUNTIME_DIR", str(run))
    monkeypatch.setenv("GTECAT_INSPECT", "1")
    return run / "gtecat"


@pytest.fixture
def app(runtime_dir: Path, tmp_path: Path) -> Iterator[object]:
    """An application as a user writes it (GT_Open, bus up, axes on), lockstep clock."""
    from gtecat import gt

    assert gt.GT_Open(eni=str(FIG5_2), clock="lockstep", log=str(tmp_path / "Gecat.log")) == 0
    try:
        assert gt.GT_Reset() == 0
        assert gt.GT_InitEcatComm() == 0
        ready = ctypes.c_short()
        for _ in range(100):
            gt.GTE_Wait(1)
            gt.GT_IsEcatReady(ctypes.byref(ready))
            if ready.value:
                break
        assert ready.value == 1
        assert gt.GT_StartEcatComm() == 0
        for axis in (1, 2):
            assert gt.GT_AxisOn(axis) == 0
        yield gt
    finally:
        gt.GT_Close()
