"""The 12-axis cell that meets trouble (tools/session_cell.py), recorded with every cycle run one
at a time - no run of cycles at once, no quick cycle a call's latency makes due (conftest's
record_one_by_one) - and replayed the quick ways: every call's result the same.  Its faults
and homings come at the same fractions of a shorter session: a few virtual seconds here, the
whole minute under GTECAT_LONG=1.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gtecat import faults, gt
from gtecat.faults.record import replay
from tests.conftest import LONG
from tests.gtecat.faults.conftest import record_one_by_one
from tools import session_cell

SECONDS = 60.0 if LONG else 4.0


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("cell")
    machine = folder / "cell.toml"
    machine.write_text(session_cell.machine(SECONDS))
    return record_one_by_one(
        folder / "cell.gtrec",
        lambda: session_cell.session(gt, faults, SECONDS, str(machine)),
        quick=False,
    )


def test_the_cell_meets_its_trouble(recorded: Path) -> None:
    calls = [json.loads(x) for x in recorded.read_text().splitlines()[1:] if '"c":' in x]
    named = {}
    for e in calls:
        named.setdefault(e["c"], []).append(e)
    # the cut interrupts a smart homing (the first in a short session), which starts again
    assert len(named["GT_GoHome"]) >= 2
    ready = [e.get("o", {}).get("0", {}).get("ref", {}).get("v") for e in named["GT_IsEcatReady"]]
    assert 0 in ready[ready.index(1) :]  # the cut, once the bus was up
    lost = [e for e in named["GT_EcatSDOUpload"] if e["r"] != 0]
    assert lost and lost[0]["o"]["6"]["ref"]["v"] == 0x05040000  # the answer lost
    assert len(named["GT_ClrSts"]) >= 5  # the drive resets, the limits cleared
    assert sum(e["c"] == "GT_GetSts" and e["a"][0] == 12 for e in calls) >= SECONDS * 80  # polled


def test_the_cell_replays_exactly_the_quick_ways(recorded: Path) -> None:
    n, div = replay(recorded)
    assert div is None, str(div)
    assert n == sum('"c":' in x for x in recorded.read_text().splitlines()[1:])
