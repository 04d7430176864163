"""Drives standing in homing mode before their homing, in the axis bank and on the scalar path.

An application switches its axes to homing mode (GT_SetHomingMode(a, 6)) one after the
other, sets their parameters and starts them later: meanwhile each drive stands with no
procedure started, a bank row whose cycle changes nothing (the servo on).  Twelve axes are
switched at different cycles and left standing for many cycles; then they are started at
different cycles (methods 35 and 37 at once, a limit and a home-switch search), one by a raw
write of its controlword, one is switched back to CSP, one switched off and on again, one
stands on its negative limit switch (its flag latched, GT_ClrSts on it), one gets its
parameters again while it stands.  Compared exactly with the bank off: every axis's
GT_GetSts word, planned and encoder positions, GT_GetEcatHomingStatus, the enable outputs
(GT_GetDo) and the whole GT raw image after every cycle the loop sees, and the drives'
mechanics at the end.
"""

from __future__ import annotations

from ctypes import byref, c_long, c_ubyte

import pytest

from gtecat import gt
from gtecat.controller import bank_kernel
from tests.gtecat.controller.test_bank import ENI, HAS_CC, _ok, open_bus
from tests.gtecat.controller.test_bank_homing import _machine, _mechanics, _sample

AXES = 12
#: axis -> (method, machine keys)
SETUP: dict[int, tuple[int, dict[str, object]]] = {
    1: (35, {}),
    2: (37, {}),
    3: (17, {"negative_limit": -9_000}),
    4: (35, {}),
    5: (37, {}),
    6: (35, {}),
    7: (37, {}),
    8: (35, {}),
    9: (35, {"negative_limit": 0}),  # stands on its negative limit switch
    10: (37, {}),
    11: (19, {"home_switch": [[5_000, 900_000]]}),
    12: (35, {}),
}
CYCLES = 420


def _prm(a: int) -> None:
    _ok(gt.GT_SetEcatHomingPrm(a, SETUP[a][0], 30_000, 8_000, 800_000, 10 * a, 0), "prm")


def _run(machine: str, bank: str) -> tuple[list, int]:
    trace: list = []
    try:
        open_bus(str(ENI), machine, bank)
        for a in SETUP:
            _ok(gt.GT_AxisOn(a), f"axis on {a}")
        ctl = gt.GTE_Controller()
        size = ctl.layout.gt_raw_bytes
        # 6040h of axis 3 (the third one-channel drive)
        cw3 = next(e for e in ctl.layout.slaves[2].entries if e.index == 0x6040).gt_bit >> 3
        for k in range(CYCLES):
            if k % 4 == 0 and 1 <= k // 4 <= AXES:  # switched one after the other, left standing
                a = k // 4
                _ok(gt.GT_SetHomingMode(a, 6), f"homing mode {a}")
                _prm(a)
            if k == 100:
                _ok(gt.GT_StartEcatHoming(1), "start 1")
            if k == 120:
                _ok(gt.GT_StartEcatHoming(2), "start 2")
            if k == 140:  # CW4 rises by a raw write: the drive starts its search by itself
                _ok(gt.GT_SetEcatRawData(cw3, 1, (c_ubyte * 1)(0x1F)), "raw")
            if k == 150:
                _ok(gt.GT_SetHomingMode(5, 8), "back to CSP")
            if k == 160:
                _ok(gt.GT_AxisOff(6), "axis off")
            if k == 170:
                _ok(gt.GT_ClrSts(9), "clear on the limit")
            if k == 180:
                _prm(10)  # its parameters again while it stands
            if k == 200:
                _ok(gt.GT_AxisOn(6), "axis on again")
            if k == 220:
                for a in (7, 8):
                    _ok(gt.GT_StartEcatHoming(a), f"start {a}")
            if k == 260:
                for a in (4, 6, 9, 10, 11, 12):
                    _ok(gt.GT_StartEcatHoming(a), f"start {a}")
            if k == 330:
                _ok(gt.GT_SetHomingMode(1, 8), "axis 1 back to CSP")
            gt.GTE_Wait(1)
            enabled = c_long()  # the axes' enable outputs (servo on): the rows' own bit
            _ok(gt.GT_GetDo(gt.MC_ENABLE, byref(enabled)), "enable outputs")
            trace.append((*_sample(size), enabled.value))
        bank = ctl.bank
        frozen = bank.frozen_rows_run if bank is not None else 0
        trace.append(_mechanics(ctl))
    finally:
        gt.GT_Close()
    return trace, frozen


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> tuple:
    machine = _machine(tmp_path_factory.mktemp("idle"), SETUP)
    return _run(machine, "off"), _run(machine, "on")


def test_standing_in_homing_mode_in_the_bank_matches_the_scalar_drives(runs: tuple) -> None:
    (ref, ref_rows), (got, _) = runs
    assert ref_rows == 0
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"cycle {k}: the bank and the scalar drives differ"
    # homed (3) but axis 5, back in CSP before its start (5: not homed); axis 3 homed on its
    # limit after the raw write's start; axis 11 still searching for its home switch (0)
    status = ref[-2][3]
    assert status[4] == 5 and status[0] == status[1] == 3
    assert status[10] == 0


def test_the_bank_ran_the_standing_drives(runs: tuple) -> None:
    """Without this the differential test could pass with the bank never engaged."""
    if not HAS_CC:
        pytest.skip("no C compiler: homing rows run only in the compiled cycle")
    if bank_kernel.wanted() == "numpy":
        pytest.skip("GTECAT_BANK_KERNEL=numpy: homing rows run only in the compiled cycle")
    _, (_, frozen) = runs
    # axis-cycles skipped: the standing drives' (axis 6's 40 cycles switched off are a few
    # of them)
    assert frozen > 1500
