"""GTE_Wait's C entry under the recorder and in a replay: a session that polls between waits
(whole milliseconds as ints and as floats, a fraction, a Trap move ending inside a wait, a
drive fault scripted at a controller time) records the same lines with the entry as with
the Python fast function, and its replay - whose waits the entry makes - matches, with the
C loop and without it."""

from __future__ import annotations

from ctypes import byref, c_double, c_long
from pathlib import Path

import pytest

from gtecat import faults, gt
from gtecat.faults import record as rec

from .conftest import fig5_2_jogging, recorded

pytestmark = pytest.mark.skipif(
    not hasattr(gt.GTE_Wait, "python"), reason="no C entry for GTE_Wait here"
)


def _session() -> None:
    fig5_2_jogging(3.0)
    assert gt.GT_AxisOn(2) == 0
    faults.inject("drive_fault", axis=2, code=0x2310, after_ms=150, duration_ms=30)
    sts, pos = c_long(), c_double()
    waits = (1, 1.0, 2, 0.5, 3, 0)
    for k in range(240):
        if k % 80 == 5:  # (a short move: it ends inside a wait)
            gt.GT_PrfTrap(2)
            prm = gt.TTrapPrm()
            prm.acc = prm.dec = 0.5
            gt.GT_SetTrapPrm(2, byref(prm))
            gt.GT_SetPos(2, 300 if k % 160 == 5 else 0)
            gt.GT_SetVel(2, 5.0)
            gt.GT_Update(2)
        for a in (1, 2):
            gt.GT_GetSts(a, byref(sts))
            gt.GT_GetEncPos(a, byref(pos))
        gt.GTE_Wait(waits[k % len(waits)])


def _calls(path: Path) -> list[str]:
    return [x for x in path.read_text().splitlines() if x.startswith('{"t":')]


def test_the_entry_records_and_replays_its_waits(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    entry = recorded(tmp_path / "entry.gtrec", _session)
    with monkeypatch.context() as mp:
        mp.setattr(gt, "GTE_Wait", gt.GTE_Wait.python)
        python = recorded(tmp_path / "python.gtrec", _session)
    lines = _calls(entry)
    assert sum('"c":"GTE_Wait"' in x for x in lines) >= 240  # (every wait recorded)
    assert lines == _calls(python)
    # (the fault fired inside a wait: axis 2's alarm read)
    assert any('"c":"GT_GetSts","a":[2' in x and '"o"' in x for x in lines)
    for loop in (True, False):
        monkeypatch.setattr(rec, "C_LOOP", loop)
        n, div = rec.replay(entry)
        assert div is None, div
        assert n == len(lines)
