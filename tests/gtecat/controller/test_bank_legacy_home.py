"""The older cards' homing (GT_HomeInit, GT_Index, GT_Home, GT_HomeStop, GT_HomeSts) in the
axis bank against the scalar path, cycle by cycle.

Twelve EtherCAT axes home at once with different switches, directions, speeds and offsets
(the home ahead and behind the start, a search that starts on the switch, GT_HomeStop, one
home + index through the drive's touch probe, one whose search ends before any switch, one
that never homes), while an application polls every axis's GT_HomeSts after every cycle or
every few: the poll reads the homing's status without giving the axis back, so the searches
run in the bank between their events.  Compared exactly with the bank off after every
wait: GT_GetSts, planned and encoder positions, THomeStatus, every axis's GT_HomeSts (its
code and value) and the whole GT raw image; the drives' mechanics and mailbox counters at
the end.
"""

from __future__ import annotations

from ctypes import byref, c_ushort
from typing import Any

import pytest

from gtecat import gt
from tests.gtecat.controller.test_bank import ENI, _ok, open_bus
from tests.gtecat.controller.test_bank_smart_home import _end_state, _machine, _sample

AXES = 12
#: axis -> (the call: "home", "stop" (GT_HomeStop) or None (never homed), its arguments
#: (pos, vel, acc[, offset]), GT_Index's (pos, offset) or None, machine keys)
SETUP: dict[int, tuple[str | None, tuple, tuple | None, dict[str, object]]] = {
    1: ("home", (60_000, 20.0, 0.5, 100), None, {"home_switch": [[4_037, 8_000]]}),
    2: ("home", (60_000, 20.0, 0.5, -250), None, {"home_switch": [[4_074, 8_000]]}),
    3: ("home", (-60_000, 15.0, 0.25, 40), None, {"home_switch": [[-3_500, -2_111]]}),
    4: ("home", (30_000, 33.0, 1.0, 0), None, {"home_switch": [[2_222, 2_600]]}),
    5: ("stop", (60_000, 20.0, 0.5), None, {"home_switch": [[3_333, 9_000]]}),
    6: (  # starts on the switch: off it backwards, then the edge ahead
        "home",
        (60_000, 10.0, 0.5, 70),
        None,
        {"position": 1_000, "home_switch": [[500, 2_500]]},
    ),
    7: (  # home, then the first index beyond it (GT_Index before GT_Home)
        "home",
        (60_000, 20.0, 0.5, 0),
        (20_000, 300),
        {"home_switch": [[2_000, 3_000]], "index_offset": 100, "counts_per_rev": 1_000},
    ),
    8: ("home", (2_000, 20.0, 0.5, 0), None, {"home_switch": [[5_000, 6_000]]}),  # none
    9: (None, (), None, {"home_switch": [[1_000, 2_000]]}),  # never homed, polled
    10: ("home", (60_000, 25.0, 0.75, 1_000), None, {"home_switch": [[1_800, 2_200]]}),
    11: ("home", (-60_000, 20.0, 0.5, -100), None, {"home_switch": [[-5_555, -4_000]]}),
    12: ("home", (60_000, 40.0, 2.0, 11), None, {"home_switch": [[7_777, 8_888]]}),
}
CYCLES = 400


def _sts(axis: int) -> tuple[int, int]:
    s = c_ushort(7)
    rc = gt.GT_HomeSts(axis, byref(s))
    return rc, s.value


def _run(machine: str, bank: str, step: int = 0) -> tuple[list, dict[str, Any]]:
    """The homings, sampled after every wait (``step`` 0: one cycle, now and then seven;
    else ``step`` cycles at once)."""
    trace: list = []
    try:
        open_bus(str(ENI), machine, bank)
        _ok(gt.GT_HomeInit(), "home init")
        for a, (call, args, index, _) in SETUP.items():
            _ok(gt.GT_AxisOn(a), f"axis on {a}")
            if index is not None:
                _ok(gt.GT_Index(a, *index), f"index {a}")
            if call == "home":
                _ok(gt.GT_Home(a, *args), f"home {a}")
            elif call == "stop":
                _ok(gt.GT_HomeStop(a, *args), f"home stop {a}")
        ctl = gt.GTE_Controller()
        size = ctl.layout.gt_raw_bytes
        k = 0
        releases = []
        while k < CYCLES:
            wait = step or (1 if k % 50 else 7)
            gt.GTE_Wait(wait)
            k += wait
            b = ctl.bank
            before = b.releases if b is not None else 0
            polled = tuple(_sts(a) for a in SETUP)
            if b is not None:
                releases.append(b.releases - before)
            trace.append((polled, _sample(size, AXES)))
        bank_ = ctl.bank
        stats = {
            "rows": bank_.rows_run if bank_ is not None else 0,
            "poll_releases": sum(releases),
        }
        trace.append(_end_state(ctl))
    finally:
        gt.GT_Close()
    return trace, stats


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> str:
    setup = {a: (None, keys) for a, (*_, keys) in SETUP.items()}
    return _machine(tmp_path_factory.mktemp("legacy_home"), setup)


@pytest.fixture(scope="module")
def runs(machine: str) -> tuple:
    return _run(machine, "off"), _run(machine, "on")


def test_legacy_homing_in_the_bank_matches_the_scalar_path(runs: tuple) -> None:
    (ref, ref_stats), (got, _) = runs
    assert ref_stats["rows"] == 0
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"sample {k}: the bank and the scalar path differ"
    # every homing ended as planned: GT_HomeSts 1 (axis 8: no home before its end, 1
    # returned; axis 9 never homed), standing at the capture + its offset
    polled, (_, prf, _, homes, _) = ref[-2]
    ended = dict(zip(SETUP, polled, strict=True))
    assert ended[8][0] == 1 and ended[9] == (0, 0), ended
    assert all(ended[a] == (0, 1) for a in SETUP if a not in (8, 9)), ended
    for a, (call, args, index, _) in SETUP.items():
        if a in (8, 9):
            continue
        cap = homes[a - 1][3]
        offset = index[1] if index else args[3] if call == "home" else 0
        assert prf[a - 1] == cap + offset, (a, prf[a - 1], cap, offset)


def test_the_polls_leave_the_axes_in_the_bank(runs: tuple) -> None:
    """Without this the differential test could pass with every poll giving its axis back
    (each taken again at the next cycle: the same values, at many times the cost)."""
    _, (_, stats) = runs
    assert stats["rows"] > AXES * CYCLES * 0.4
    assert stats["poll_releases"] == 0


def test_long_waits_give_the_same_legacy_homings(machine: str) -> None:
    """Waits of 23 ms between the polls: the controller runs the searches' quiet cycles at
    once, the events one cycle at a time."""
    (ref, _), (got, _) = _run(machine, "off", 23), _run(machine, "on", 23)
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"after {23 * (k + 1)} cycles: the bank and the scalar path differ"
