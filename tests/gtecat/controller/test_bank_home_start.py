"""GT_StartEcatHoming of methods 35/37 on the drive's frozen bank row, against the scalar path.

The start's instant part runs on the row's objects as the cycle begins and the row is taken
as the ended homing it becomes (gtecat.controller.bank_home_start).  Compared exactly with the
bank off, on both clocks: every call's return code, every axis's GT_GetSts word, planned and
encoder positions, GT_GetEcatHomingStatus and the whole GT raw image (6040h, 6041h, 6064h
among it) after every cycle, and at the end every attribute of the started axes' objects
(axis, resources, planner, encoder, band, drive channel and its homing procedure, mechanics)
and their drives' process data buffers.  The starts: methods 35 and 37 right after the switch
and the parameters, in the same call sequence and cycles later, homed again after a return to
CSP, a start the drive refuses (no parameters), starts that take the opened row's path (a
touch probe function, a raw write to the drive's outputs just before, a method that searches,
a drive of several channels), and the same with the rows given back or refused.
"""

from __future__ import annotations

from ctypes import byref, c_short, c_ubyte
from typing import Any

import pytest

from gtecat import gt
from gtecat.controller import bank_kernel
from gtecat.controller.bank import AxisBank
from tests.gtecat.controller.test_bank import HAS_CC, _ok
from tests.gtecat.controller.test_bank_home_rows import _all_on, _ran_on_rows, _same
from tests.gtecat.controller.test_bank_home_rows import _run as _run_calls
from tests.gtecat.controller.test_bank_homing import _machine
from tests.gtecat.controller.test_bank_homing_calls import _prm

AXES = 12
SETUP: dict[int, tuple[int, dict[str, object]]] = {
    a: (0, {"home_switch": [[2_000 + 10 * a, 3_000]], "negative_limit": -300 - a})
    for a in range(1, AXES + 1)
}
CYCLES = 120


def _raw_target(a: int) -> int:
    """A raw write of a new 607Ah to axis ``a``'s outputs (its drive in homing mode takes
    the value and ignores it; the bank sees its outputs written)."""
    ctl = gt.GTE_Controller()
    e = ctl.layout.axis_entry(a, 0x607A)
    assert e is not None
    return gt.GT_SetEcatRawData(e.gt_bit >> 3, 1, (c_ubyte * 1)(0x55))


#: cycle -> the calls made before it (each one's return code goes into the trace); axes 1-4
#: are drives of one channel (their rows start on the row), 5-12 channels of drives with
#: several (their rows go back for a call)
CALLS: dict[int, list[Any]] = {
    3: [lambda: gt.GT_SetHomingMode(1, 6), lambda: _prm(1, 35), lambda: gt.GT_StartEcatHoming(1)],
    4: [lambda: gt.GT_SetHomingMode(2, 6), lambda: _prm(2, 37)],
    7: [lambda: gt.GT_StartEcatHoming(2)],  # cycles after its set-up
    8: [lambda: gt.GT_SetHomingMode(3, 6), lambda: gt.GT_StartEcatHoming(3)],  # refused
    9: [lambda: _prm(3, 35, probe=0x0011), lambda: gt.GT_StartEcatHoming(3)],  # a probe
    10: [lambda: gt.GT_SetHomingMode(4, 6), lambda: _prm(4, 37)],
    11: [lambda: _raw_target(4), lambda: gt.GT_StartEcatHoming(4)],  # outputs written
    12: [lambda: gt.GTN_SetHomingMode(1, 5, 6), lambda: _prm(5, 35)],
    13: [lambda: gt.GT_StartEcatHoming(5)],  # a drive of several channels
    20: [lambda: gt.GT_StartEcatHoming(1)],  # again, CW4 still high: two cycles
    30: [lambda: gt.GT_SetHomingMode(1, 8), lambda: gt.GT_SetHomingMode(2, 8)],
    40: [lambda: gt.GT_SetHomingMode(1, 6), lambda: _prm(1, 37)],
    41: [lambda: gt.GT_StartEcatHoming(1)],  # homed again after CSP
    42: [lambda: gt.GT_SetHomingMode(2, 6), lambda: _prm(2, 17, speed1=10_000)],
    43: [lambda: gt.GT_StartEcatHoming(2)],  # a search (the negative limit)
    50: [lambda: gt.GT_SetHomingMode(3, 8), lambda: gt.GT_SetHomingMode(3, 6)],
    51: [lambda: _prm(3, 35), lambda: gt.GT_StartEcatHoming(3), lambda: gt.GT_GetSts(3, 0)],
    60: [lambda: gt.GT_SetHomingMode(4, 8), lambda: gt.GT_SetHomingMode(4, 6)],
    61: [lambda: _prm(4, 35), lambda: gt.GT_StartEcatHoming(4), lambda: gt.GT_ClrSts(4)],
}
#: the axes whose objects are compared at the end
DEEP = (1, 2, 3, 4, 5)


def _run(machine: str, bank: str, clock: str) -> tuple[list, dict[str, Any], int]:
    return _run_calls(machine, bank, clock, CALLS, CYCLES, DEEP, "home_starts")


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> str:
    return _machine(tmp_path_factory.mktemp("home_start"), SETUP)


#: the default run takes the auto clock (test_bank_home_rows' more switches the lockstep
#: one); GTECAT_LONG=1 runs both
@pytest.fixture(
    scope="module",
    params=[pytest.param("lockstep", marks=pytest.mark.long("on the lockstep clock")), "auto"],
)
def runs(request: pytest.FixtureRequest, machine: str) -> tuple:
    clock = request.param
    return clock, _run(machine, "off", clock), _run(machine, "on", clock)


def test_starts_on_rows_match_the_scalar_drives(runs: tuple) -> None:
    _, ref, got = runs
    _same(ref, got)
    _ran_on_rows(got, 4)  # (a start on a row, at least)
    codes = [c for step in ref[0][0::2] for c in step]
    assert codes.count(0) < len(codes)  # the start without parameters was refused
    homing = ref[0][-1][3]
    assert homing[:5] == (3, 3, 3, 3, 3)  # every started drive homed (2 by its search)


def test_a_row_the_bank_would_not_take_after_its_start_goes_back(
    runs: tuple, machine: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A row whose start's instant part ran on it but which the bank would not take as the
    ended homing it became (here: told so, the first two times) goes back with its objects
    as that part left them, and the scalar path runs the rest of its cycle."""
    clock, ref, _ = runs
    homing = AxisBank._eligible_homing
    refused: list[int] = []

    def refuse_after_a_start(bank: AxisBank, r: int) -> bool:
        if bank._home_started == r and bank.frz[r] and len(refused) < 2:
            refused.append(r)
            return False
        return homing(bank, r)

    monkeypatch.setattr(AxisBank, "_eligible_homing", refuse_after_a_start)
    got = _run(machine, "on", clock)
    _same(ref, got)
    if HAS_CC and bank_kernel.wanted() != "numpy":
        assert len(refused) == 2


def test_a_start_on_its_row_keeps_the_row(machine: str) -> None:
    """The started row stays in the bank through its start and the cycles after it (nothing
    of the start reads as a raw write of its outputs, nor leaves the drive's homing
    unanswered), and its drive shows the homing's end."""
    if not HAS_CC or bank_kernel.wanted() == "numpy":
        pytest.skip("homing rows run only in the compiled cycle")
    try:
        _all_on(machine)
        _ok(gt.GT_SetHomingMode(1, 6), "mode")
        _ok(_prm(1, 35), "prm")
        gt.GTE_Wait(5)
        bank = gt.GTE_Controller().bank
        r = bank._row_of[id(gt.GTE_Controller().axes[1])]
        releases, given = bank.releases, bank.home_starts_given
        _ok(gt.GT_StartEcatHoming(1), "start")
        gt.GTE_Wait(5)
        assert (bank.home_starts, bank.home_starts_given) == (1, given)
        assert bank.releases == releases and bank.alive[r] and bank.h_done[r] == 1
        st = c_short()
        _ok(gt.GT_GetEcatHomingStatus(1, byref(st)), "status")
        assert st.value == 3
    finally:
        gt.GT_Close()


def test_a_row_given_back_right_after_its_start(
    runs: tuple, machine: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Every row given back in the cycle its start ran on it (what a bank that must stop does)
    goes on from the bank's cycle on the scalar path exactly."""
    clock, ref, _ = runs
    cycle = AxisBank._cycle
    given: list[int] = []

    def give_back_after_a_start(bank: AxisBank, t_ns: int, dt_ns: int) -> None:
        started = bank.home_starts
        cycle(bank, t_ns, dt_ns)
        if bank.home_starts != started and len(given) < 3:
            given.append(bank._home_started)
            bank.release_all()

    monkeypatch.setattr(AxisBank, "_cycle", give_back_after_a_start)
    got = _run(machine, "on", clock)
    _same(ref, got)
    if HAS_CC and bank_kernel.wanted() != "numpy":
        assert len(given) == 3
