"""Replays of a session in which controller time passed between the calls, as a controller
process lets its clock follow the wall clock while its C, C++ or C# client waits (the
entries' ``"b"``: the time each such call began at): every call replays with its own time,
the lines that differ only in their values and that time share one prepared call, and a
changed time is found where it changes a result."""

from __future__ import annotations

import json
from ctypes import byref, c_double, c_long
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.faults.record import _open_text, _steps, replay

from .conftest import fig5_2_up, recorded

POLLS = 300


def _session() -> None:
    fig5_2_up()
    gt.GT_AxisOn(1)
    gt.GT_PrfJog(1)
    gt.GT_SetVel(1, 3.0)
    gt.GT_Update(1)
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
    text = gaps.read_text().splitlines()
    seen = calls = 0
    for i, line in enumerate(text[1:], 1):
        if '"c":' not in line:
            continue
        calls += 1
        if '"c":"GT_GetSts"' in line and '"b":' in line:
            seen += 1
            if seen == 150:
                e = json.loads(line)
                e["b"] += 5_000_000  # 5 ms later: the clock read after it differs
                text[i] = json.dumps(e, separators=(",", ":"))
                break
    bad = tmp_path / "late.gtrec"
    bad.write_text("\n".join(text) + "\n")
    n, div = replay(bad)
    assert div is not None and calls <= n <= calls + 2
