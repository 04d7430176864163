"""Replays of a session in which controller time passed between the calls, as a controller
process lets its clock follow the wall clock while its C, C++ or C# client waits (the
entries' ``"b"``: the time each such call began at): every call replays with its own time,
the lines that differ only in their values and that time share one prepared call, and a
changed time is found where it changes a result."""

from __future__ import annotations

from ctypes import byref, c_double, c_long
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.faults.record import _open_text, _steps, replay

from .conftest import changed, fig5_2_jogging, recorded

POLLS = 300


def _session() -> None:
    fig5_2_jogging(3.0)
    clock = gt.GTE_Controller().clock
    s, p, clk = c_long(), c_double(), c_long()
    for i in range(POLLS):
        clock.advance_ns(700_000 + 1000 * (i % 7))  # the client away: time passes meanwhile
        gt.GT_GetSts(1, byref(s))
        gt.GT_GetPrfPos(1, byref(p))
        gt.GT_GetClock(byref(clk))
    gt.GT_Close()


@pytest.fixture(scope="module")
def gaps(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return recorded(tmp_path_factory.mktemp("gaps") / "gaps.gtrec", _session)


def test_each_call_replays_with_its_own_time_and_the_lines_share_forms(gaps: Path) -> None:
    lines = [x for x in gaps.read_text().splitlines()[1:] if '"c":"GT_GetSts"' in x]
    assert sum('"b":' in x for x in lines) >= POLLS - 1  # (each poll began after a gap)
    assert len({x[x.find(",") :] for x in lines}) > POLLS // 2  # (distinct lines: the times)
    _, div = replay(gaps)
    assert div is None, str(div)
    p, _, body = _open_text(gaps, gaps.read_bytes())
    made = {id(c) for c, _ in _steps(p, body) if c is not None and c.name == "GT_GetSts"}
    assert len(made) <= 3  # (with and without a gap, written back or not)


def test_a_changed_time_is_found(gaps: Path, tmp_path: Path) -> None:
    def later(e: dict) -> None:
        e["b"] += 5_000_000  # 5 ms later: the clock read after it differs

    bad = tmp_path / "late.gtrec"
    calls = changed(
        gaps, bad, lambda line: '"c":"GT_GetSts"' in line and '"b":' in line, 150, later
    )
    n, div = replay(bad)
    assert div is not None and calls <= n <= calls + 2
