"""Drive homing past its search in the axis bank against the scalar reference, cycle by cycle.

Twelve axes (two per drive, each drive's pair homing alike) run the phases after a switch
is found: the reversal on a limit switch with the limit's flag latched in GT_GetSts, the
slow approach and the index search, the move back onto the home point, the completion, a
home on a limit switch (resting on it, its flag latched), a search failing on a limit
switch (braking, then resting on the switch) and GT_ClrSts on axes whose limit is still
active.  Compared exactly with the bank off: every axis's GT_GetSts word, planned and
encoder positions, GT_GetEcatHomingStatus and the whole GT raw image each cycle, the
drives' mechanics at the end; and the bank must have held rows in each of those phases.
"""

from __future__ import annotations

import pytest

from gtecat import gt
from gtecat.controller import bank_kernel
from tests.gtecat.controller.test_bank import ENI, HAS_CC, _ok, open_bus
from tests.gtecat.controller.test_bank_homing import AXES, _machine, _mechanics, _sample

_FAR = {"positive_limit": 20_000, "negative_limit": -20_000}
#: axis -> (method, machine keys)
SETUP: dict[int, tuple[int, dict[str, object]]] = {
    # negative limit, then the first index pulse right of its edge
    1: (1, {**_FAR, "negative_limit": -3_000, "index_offset": 300, "counts_per_rev": 2_000}),
    2: (1, {**_FAR, "negative_limit": -3_400, "index_offset": 500, "counts_per_rev": 2_000}),
    # home on the negative limit's edge: at rest on the switch afterwards
    3: (17, {**_FAR, "negative_limit": -2_500}),
    4: (17, {**_FAR, "negative_limit": -2_800}),
    # cam low edge: from outside it, and from inside it (a reversal on the edge)
    5: (24, {**_FAR, "home_switch": [[2_000, 4_000]]}),
    6: (24, {**_FAR, "home_switch": [[-1_000, 3_000]]}),
    # a negative home switch never met: the search fails on the negative limit switch
    7: (21, {**_FAR, "home_switch": [[5_000, 7_000]], "negative_limit": -2_000}),
    8: (21, {**_FAR, "home_switch": [[5_000, 7_000]], "negative_limit": -2_200}),
    # positive limit, then the first index pulse left of its edge
    9: (2, {**_FAR, "positive_limit": 3_000, "index_offset": 100, "counts_per_rev": 1_500}),
    10: (2, {**_FAR, "positive_limit": 3_300, "index_offset": 700, "counts_per_rev": 1_500}),
    # cam high edge: reverse on the negative limit (its flag latched), then search on
    11: (27, {**_FAR, "home_switch": [[1_000, 2_500]], "negative_limit": -2_000}),
    12: (27, {**_FAR, "home_switch": [[1_500, 2_800]], "negative_limit": -2_300}),
}
CYCLES = 1_100
CLEAR_AT = 900  # GT_ClrSts of every axis (flags whose switch is still active stay)


def _held(ctl: object, seen: set) -> None:
    """What the bank holds this cycle: (phase, row kind, a limit flag latched, on a limit
    switch, moving) of each homing row it runs (read past its guards)."""
    bank = ctl.bank  # type: ignore[attr-defined]
    if bank is None or not bank.n_alive:
        return
    get = object.__getattribute__
    for r in range(bank.n):
        if bank.alive[r] and bank.hm[r]:
            h = get(bank.csp.channels[r], "homing")
            seen.add(
                (
                    h.phase.name,
                    int(bank.h_done[r]),
                    bool(bank.latched[r] & 0x60),
                    bool(bank.csp.din[r] & 3),
                    bank.h_v[r] != 0.0,
                )
            )


def _run(machine: str, bank: str) -> tuple[list, set]:
    trace: list = []
    seen: set = set()
    try:
        open_bus(str(ENI), machine, bank)
        for a, (method, _) in SETUP.items():
            _ok(gt.GT_ClrSts(a, 1), f"clear {a}")
            _ok(gt.GT_AxisOn(a), f"axis on {a}")
            _ok(gt.GT_SetHomingMode(a, 6), f"homing mode {a}")
            _ok(gt.GT_SetEcatHomingPrm(a, method, 20_000, 5_000, 400_000, 0, 0), "prm")
        for a in SETUP:
            _ok(gt.GT_StartEcatHoming(a), f"start {a}")
        ctl = gt.GTE_Controller()
        size = ctl.layout.gt_raw_bytes
        for k in range(CYCLES):
            if k == CLEAR_AT:
                _ok(gt.GT_ClrSts(1, AXES), "clear all")
            gt.GTE_Wait(1)
            trace.append(_sample(size))
            _held(ctl, seen)
        trace.append(_mechanics(ctl))
    finally:
        gt.GT_Close()
    return trace, seen


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> tuple:
    machine = _machine(tmp_path_factory.mktemp("homing_phases"), SETUP)
    return _run(machine, "off"), _run(machine, "on")


def test_homing_phases_in_the_bank_match_the_scalar_drives(runs: tuple) -> None:
    (ref, seen_off), (got, _) = runs
    assert not seen_off
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"cycle {k}: the bank and the scalar drives differ"
    # homed (3) but axes 7 and 8, failed on their negative limit switch (5)
    assert ref[-2][3] == (3, 3, 3, 3, 3, 3, 5, 5, 3, 3, 3, 3)
    sts = ref[-2][0]
    assert [bool(s & 0x40) for s in sts[:8]] == [False] * 2 + [True] * 2 + [False] * 2 + [True] * 2


def test_the_bank_ran_the_phases(runs: tuple) -> None:
    """Without this the differential test could pass with the bank never engaged."""
    if not HAS_CC:
        pytest.skip("no C compiler: homing rows run only in the compiled cycle")
    if bank_kernel.wanted() == "numpy":
        pytest.skip("GTECAT_BANK_KERNEL=numpy: homing rows run only in the compiled cycle")
    _, (_, seen) = runs
    phases = {s[0] for s in seen}
    assert {"SEARCH", "APPROACH", "INDEX", "RETURN", "COMPLETED", "FAILED"} <= phases
    # a search with a limit's flag latched (after the reversal on it)
    assert any(s[0] in ("SEARCH", "APPROACH", "INDEX") and s[2] for s in seen)
    assert any(s[0] == "RETURN" and s[1] == 2 for s in seen)  # back onto the home point
    assert any(s[0] == "FAILED" and s[4] for s in seen)  # braking after the failure
    # at rest on a limit switch, its flag latched: homed on it, failed on it
    assert ("COMPLETED", 1, True, True, False) in seen
    assert ("FAILED", 1, True, True, False) in seen
