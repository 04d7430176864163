"""Replays of the hard-polling application (tools/session_hard.py), for a fraction of a virtual
second: polled one axis per call and as count-12 arrays, each replays exactly; an encoder read
of more than 8 axes at once is refused by the fast path with the table path's code and reason.
"""

from __future__ import annotations

from ctypes import c_double
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.faults.record import replay
from tools import session_hard

SECONDS = 0.25


@pytest.mark.parametrize("single", [True, False], ids=["one_by_one", "arrays"])
def test_the_session_replays_exactly(tmp_path: Path, single: bool) -> None:
    out = tmp_path / "hard.gtrec"
    try:
        session_hard.record(out, SECONDS, single)
    finally:
        gt.GT_Close()
    calls = [x for x in out.read_text().splitlines()[1:] if '"c":' in x]
    shape = '"c":"GT_GetSts","a":[3,' if single else '"c":"GT_GetSts","a":[1,{"arr"'
    assert sum(shape in x for x in calls) >= 40  # polled every 4 ms
    n, div = replay(out)
    assert div is None, str(div)
    assert n == len(calls)


def test_more_encoders_than_a_call_reads_are_refused_as_the_table_refuses_them() -> None:
    assert gt.GT_Open(eni=str(session_hard.ENI), clock="lockstep", log="") == 0
    assert gt.GT_InitEcatComm() == 0
    gt.GTE_Wait(60)
    enc = (c_double * 12)()
    for fn in (gt.GT_GetEncPos, gt.GT_GetEncPos.slow):
        assert fn(1, enc, 12, None) == 7
        assert gt.GTE_GetLastError() == "GT_GetEncPos returned 7: count=12: at most 8 at once"
