"""A drive homing's set-up and start on rows the bank opens for the call, against the scalar path.

GT_SetHomingMode, GT_SetEcatHomingPrm and GT_StartEcatHoming run on their axis's bank row
opened for the call (the cycles they wait for step the row's objects in the bank's cycle),
or, for a frozen row a call leaves frozen, with the row kept; where per-cycle hooks run (a
smart homing on another axis) the row goes back for the call instead.  The calls that
matter: switched from CSP, given parameters, started (methods 35, 37 and a limit search),
refused (a start before the mode or the parameters, a parameter out of range, a mode
switch while a Trap move runs), a probe function with the parameters, back to CSP after a
homing and homed again, and the same calls while a smart homing on axis 12 hooks every
cycle.  Compared exactly with the bank off: every call's return code, every axis's
GT_GetSts word, planned and encoder positions, GT_GetEcatHomingStatus, the enable outputs
and the whole GT raw image after every cycle, and the drives' mechanics at the end.
"""

from __future__ import annotations

from ctypes import byref, c_long
from typing import Any

import pytest

from gtecat import gt
from gtecat.controller import bank_kernel
from gtecat.controller.bank import AxisBank
from tests.gtecat.controller.test_bank import ENI, HAS_CC, _ok, open_bus
from tests.gtecat.controller.test_bank_homing import _machine, _mechanics, _sample

#: axis -> (method, machine keys); axes 1-4 are drives of one channel (the rows opened)
SETUP: dict[int, tuple[int, dict[str, object]]] = {
    1: (35, {"probe1": [[-500, 500]]}),
    2: (37, {}),
    3: (35, {}),
    4: (17, {"negative_limit": -3_000}),
    12: (0, {"home_switch": [[2_000, 3_000]]}),  # smart homing, from cycle 150 on
}
CYCLES = 380


def _prm(a: int, method: int, probe: int = 0, speed1: float = 30_000) -> int:
    return gt.GT_SetEcatHomingPrm(a, method, speed1, 8_000, 800_000, 10 * a, probe)


def _trap(a: int) -> int:
    prm = gt.TTrapPrm()
    prm.acc = prm.dec = 0.5
    prm.smoothTime = 0
    for rc in (
        gt.GT_PrfTrap(a),
        gt.GT_SetTrapPrm(a, byref(prm)),
        gt.GT_SetPos(a, 1_500),
        gt.GT_SetVel(a, 20.0),
        gt.GT_Update(1 << (a - 1)),
    ):
        if rc:
            return rc
    return 0


def _go_home(a: int) -> int:
    rc = gt.GT_PrfTrap(a)
    prm = gt.THomePrm()
    prm.mode, prm.moveDir, prm.indexDir, prm.edge, prm.triggerIndex = 20, 1, -1, 0, -1
    prm.velHigh, prm.velLow, prm.acc, prm.dec = 20.0, 4.0, 1.0, 1.0
    prm.escapeStep = 1000
    return rc or gt.GT_GoHome(a, byref(prm))


#: cycle -> the calls made before it (each one's return code goes into the trace)
CALLS: dict[int, list[Any]] = {
    5: [lambda: gt.GT_SetHomingMode(1, 6), lambda: _prm(1, 35)],
    10: [lambda: _prm(1, 35, probe=0x0011)],  # a probe function: the row is looked at again
    15: [lambda: gt.GT_StartEcatHoming(2)],  # refused: not in homing mode (a CSP row)
    20: [lambda: gt.GT_SetHomingMode(2, 6)],
    22: [lambda: gt.GT_StartEcatHoming(2)],  # refused: no parameters (a frozen row)
    25: [lambda: _prm(2, 37, speed1=-1)],  # refused: out of range (a frozen row kept)
    30: [lambda: _prm(2, 37)],
    40: [lambda: gt.GT_StartEcatHoming(2), lambda: gt.GT_StartEcatHoming(1)],
    50: [lambda: _trap(3)],
    55: [lambda: gt.GT_SetHomingMode(3, 6)],  # refused: a Trap move runs (a moving row)
    80: [lambda: gt.GTN_SetHomingMode(1, 4, 6), lambda: _prm(4, 17)],
    85: [lambda: gt.GTN_StartEcatHoming(1, 4)],  # a limit search: a searching row after it
    120: [lambda: gt.GT_SetHomingMode(2, 8)],  # back to CSP after its homing (a resting row)
    130: [lambda: gt.GT_SetHomingMode(2, 6), lambda: _prm(2, 35)],
    140: [lambda: gt.GT_StartEcatHoming(2)],  # homed again
    150: [lambda: _go_home(12)],  # a smart homing: its hooks run every cycle from now on
    160: [lambda: gt.GT_SetHomingMode(1, 8)],
    170: [lambda: gt.GT_SetHomingMode(1, 6), lambda: _prm(1, 37)],
    175: [lambda: gt.GT_StartEcatHoming(1)],
    200: [lambda: gt.GT_SetHomingMode(3, 6), lambda: _prm(3, 35)],
    210: [lambda: gt.GT_StartEcatHoming(3)],
}


def _run(machine: str, bank: str) -> tuple[list, tuple[int, int, int]]:
    trace: list = []
    try:
        open_bus(str(ENI), machine, bank)
        for a in range(1, 13):
            _ok(gt.GT_AxisOn(a), f"axis on {a}")
        ctl = gt.GTE_Controller()
        size = ctl.layout.gt_raw_bytes
        for k in range(CYCLES):
            trace.append(tuple(call() for call in CALLS.get(k, ())))
            gt.GTE_Wait(1)
            enabled = c_long()
            _ok(gt.GT_GetDo(gt.MC_ENABLE, byref(enabled)), "enable outputs")
            trace.append((*_sample(size), enabled.value))
        bank = ctl.bank
        counts = (0, 0, 0)
        if bank is not None:
            # (a switch to homing mode and a start run on the row reach the row too:
            # bank_home_rows, bank_home_start)
            opened = bank.calls_opened + bank.home_switches + bank.home_starts
            counts = (opened, bank.calls_kept, bank.calls_held_out)
        trace.append(_mechanics(ctl))
    finally:
        gt.GT_Close()
    return trace, counts


def _same(ref: list, got: list) -> None:
    """Every step of a run with the bank as the scalar drives' run (the first that differs)."""
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"step {k}: the bank and the scalar drives differ"


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> tuple:
    machine = _machine(tmp_path_factory.mktemp("calls"), SETUP)
    return _run(machine, "off"), _run(machine, "on")


def test_homing_calls_on_opened_rows_match_the_scalar_drives(runs: tuple) -> None:
    (ref, _), (got, _) = runs
    _same(ref, got)
    codes = [c for step in ref[0 : 2 * CYCLES : 2] for c in step]
    assert codes.count(0) < len(codes)  # the refusals above were refused
    status = ref[-2][3]
    assert status[:4] == (3, 3, 3, 3)  # every drive homed in the end


def test_the_bank_opened_kept_and_gave_back_rows(runs: tuple) -> None:
    """Without this the differential test could pass with the calls never reaching a row."""
    if not HAS_CC:
        pytest.skip("no C compiler: homing rows run only in the compiled cycle")
    if bank_kernel.wanted() == "numpy":
        pytest.skip("GTECAT_BANK_KERNEL=numpy: homing rows run only in the compiled cycle")
    _, (_, (opened, kept, held_out)) = runs
    assert opened >= 8 and kept >= 2 and held_out >= 3


def test_a_row_given_back_while_opened_runs_on_the_scalar_path(
    runs: tuple, monkeypatch: pytest.MonkeyPatch, tmp_path_factory: pytest.TempPathFactory
) -> None:
    """Every row given back in the middle of a call on an opened row (what a bank that must
    stop does: a hook added, the bus leaving OP) leaves that row to the controller and the
    bus for the rest of the call, and the call's end takes it as any released row."""
    step = AxisBank._step_opened
    given: list[int] = []

    def step_then_give_back(bank: AxisBank, t_ns: int, dt_ns: int) -> None:
        step(bank, t_ns, dt_ns)
        if bank._opened and len(given) < 3:
            given.append(next(iter(bank._opened)))
            bank.release_all()

    monkeypatch.setattr(AxisBank, "_step_opened", step_then_give_back)
    (ref, _), _ = runs
    got, _ = _run(_machine(tmp_path_factory.mktemp("given"), SETUP), "on")
    _same(ref, got)
    if HAS_CC and bank_kernel.wanted() != "numpy":
        assert len(given) == 3


def test_a_row_claimed_while_another_is_opened_keeps_the_output_references(
    runs: tuple, monkeypatch: pytest.MonkeyPatch, tmp_path_factory: pytest.TempPathFactory
) -> None:
    """A group given back and taken again while a row is opened for a call (the bank's look
    for rows to claim comes in the middle of a call): the opened row's output bytes go to
    the places the claimed pattern of the moment gives them in the raw-write checks'
    references (a 64-axis bus's last drive found them past the end and the call failed)."""
    step = AxisBank._step_opened
    entries = AxisBank._took_entries
    moved: list[int] = []
    checked: list[int] = []

    def step_then_give_one_back(bank: AxisBank, t_ns: int, dt_ns: int) -> None:
        step(bank, t_ns, dt_ns)
        if not bank._opened or len(moved) >= 4:
            return
        gi = bank.group_of[next(iter(bank._opened))]
        before = [g for g in bank.groups[:gi] if g.claimed and bank.alive[g.rows[0]]]
        if before:  # (taken again at the next cycle's look: the pattern moves under the row)
            moved.append(gi)
            bank._release_groups(before[:1])
            bank._reindex()
            bank.dirty = True

    def checked_entries(bank: AxisBank, gi: int) -> int | None:
        at = entries(bank, gi)
        start, stop = bank._rx_start[gi], bank._rx_start[gi + 1]
        if at is not None:  # (the group's bytes, in order, from there on)
            for i, k in enumerate(range(start, stop)):
                assert int(bank._rx_idx[at + i]) == int(bank._rx_all[k])
        checked.append(stop - start)
        return at

    monkeypatch.setattr(AxisBank, "_step_opened", step_then_give_one_back)
    monkeypatch.setattr(AxisBank, "_took_entries", checked_entries)
    (ref, _), _ = runs
    got, _ = _run(_machine(tmp_path_factory.mktemp("moved"), SETUP), "on")
    _same(ref, got)
    if HAS_CC and bank_kernel.wanted() != "numpy":
        assert moved and checked
