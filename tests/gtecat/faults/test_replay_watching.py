"""Triggers that watch the machine (``when_position``, ``at_homing``) on the 12-axis cell
(tools/session_cell.py): while they wait, every axis stays on the axis bank and the cycles
run the compiled way; each fires in the very cycle it fires in when every cycle runs one at
a time, and in the scalar path without the bank.  The session is recorded the reference
ways and replayed the quick ways: every call's result the same.

The faults they arm: a link loss behind slave 3 when axis 5's smart homing passes 40000 (the
watched axis is behind the cut), one behind slave 6 when axis 1's drive homing reaches its
index stage, a drive fault of axis 9 when axis 2 (a Trap move) passes 20000, and a noisy
encoder of axis 6 when axis 1's homing has completed.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from gtecat import faults, gt
from gtecat.faults.injector import Injector
from gtecat.faults.record import replay
from tests.gtecat.faults.conftest import record_one_by_one
from tools import session_cell

# (the four watched faults fire in cycles 1074, 1352, 1744 and 2720 and the last has ended
# at 2.82 s, whatever the session's length: the virtual seconds after them proved nothing)
SECONDS = 3.0
WATCHING = (
    {"kind": "link_down", "after_slave": 3, "when_position": [5, 40000], "duration_ms": 120},
    {"kind": "link_down", "after_slave": 6, "at_homing": [1, "index"], "duration_ms": 50},
    {
        "kind": "drive_fault",
        "axis": 9,
        "code": 0x2310,
        "when_position": [2, 20000],
        "duration_ms": 150,
    },
    {
        "kind": "encoder_noise",
        "axis": 6,
        "counts": 4,
        "at_homing": [1, "completed"],
        "duration_ms": 100,
    },
)


class _Watching:
    """``gtecat.faults`` whose first ``inject`` arms :data:`WATCHING` first."""

    def __init__(self) -> None:
        self.armed = False

    def inject(self, *args: Any, **kw: Any) -> int:
        if not self.armed:
            self.armed = True
            for spec in WATCHING:
                spec = dict(spec)
                faults.inject(spec.pop("kind"), **spec)
        return faults.inject(*args, **kw)

    def __getattr__(self, name: str) -> Any:
        return getattr(faults, name)


def _record(folder: Path, bank: str, mp: pytest.MonkeyPatch) -> Path:
    machine = folder / "cell.toml"
    machine.write_text(session_cell.machine(SECONDS))
    started: list[str] = []
    start = Injector._start

    def _start(inj: Injector, e: Any) -> None:
        started.append(e.describe())
        start(inj, e)

    mp.setenv("GTECAT_BANK", bank)
    mp.setattr(Injector, "_start", _start)
    try:
        out = record_one_by_one(
            folder / f"cell-{bank}.gtrec",
            lambda: session_cell.session(gt, _Watching(), SECONDS, str(machine)),
            quick=False,
        )
    finally:
        mp.undo()
    assert sum(" passes " in x or "homing of axis" in x for x in started) == len(WATCHING)
    return out


@pytest.mark.parametrize(
    "bank",
    [
        "auto",
        # (the default run: the bank's; without the bank, a position trigger fires in the
        # cycle it fires in with the bank in test_fast_path, and a session with trouble
        # replays exactly in test_replay_rich)
        pytest.param("off", marks=pytest.mark.long("the session recorded without the bank")),
    ],
)
def test_watching_triggers_fire_in_the_same_cycle_the_quick_ways(
    bank: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    recorded = _record(tmp_path, bank, monkeypatch)
    n, div = replay(recorded)
    assert div is None, str(div)
    assert n == sum('"c":' in x for x in recorded.read_text().splitlines()[1:])
