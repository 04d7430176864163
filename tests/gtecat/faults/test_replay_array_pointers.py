"""Replays of arrays passed by pointer, ``byref(arr)`` (how a controller process records a
C, C++ or C# client's ``double *`` / ``long *``): every line of a form shares one prepared
call with its array pooled, the session replays exactly, and a changed element is named."""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_ubyte
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.faults.record import _open_text, _steps, replay

from .conftest import changed, fig5_2_jogging, recorded

POLLS = 200


def _session() -> None:
    fig5_2_jogging(4.0)
    enc = (c_double * 2)()
    sts = (c_long * 2)()
    raw = (c_ubyte * 8)()
    for _ in range(POLLS):
        gt.GT_GetEncPos(1, byref(enc), 2, None)
        gt.GT_GetSts(1, byref(sts), 2, None)
        gt.GT_GetEcatRawData(0, 8, byref(raw))
        gt.GTE_Wait(1)
    gt.GT_Close()


@pytest.fixture(scope="module")
def pointers(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return recorded(tmp_path_factory.mktemp("ptr") / "ptr.gtrec", _session)


def test_the_pointers_share_forms_and_replay_exactly(pointers: Path) -> None:
    text = pointers.read_text()
    assert text.count('"a":[1,{"ref":{"arr":"c_double","n":2,"v":[') == POLLS
    assert text.count('"a":[0,8,{"ref":{"arr":"c_ubyte","n":8,"hex":"') == POLLS
    _, div = replay(pointers)
    assert div is None, str(div)
    p, _, body = _open_text(pointers, pointers.read_bytes())
    made = {}
    for call, _ in _steps(p, body):
        if call is not None and call.name in ("GT_GetEncPos", "GT_GetEcatRawData"):
            made.setdefault(call.name, set()).add(id(call))
    # (written back or left as it was: at most two forms each, not one call per line)
    assert all(len(ids) <= 2 for ids in made.values()), made


def test_a_changed_element_behind_a_pointer_is_named(pointers: Path, tmp_path: Path) -> None:
    def nudge(e: dict) -> None:
        e["o"]["1"]["ref"]["v"][1] += 1.0

    bad = tmp_path / "bad.gtrec"
    picked = lambda line: '"c":"GT_GetEncPos"' in line and '"o":' in line  # noqa: E731
    calls = changed(pointers, bad, picked, 120, nudge)
    n, div = replay(bad)
    assert div is not None and (n, div.call, div.what) == (
        calls,
        "GT_GetEncPos",
        "argument 2 element [1]",
    )
