"""Drive homing polled between waits: the quick cycles (the readers' C entries, the auto
clock's due cycle, the waits' runs) give the machine of cycles run one by one.

Two drives of the manual's figure 5-2 bus home by themselves (mode 6, method 2: positive
limit switch, then the index pulse) while a program polls them every millisecond: clock,
homing status and encoder of each axis still homing.  Each homing event (a switch edge, an
index pulse) makes the bank's compiled cycle decline: that cycle goes the general way and
gives its homing rows back to the scalar drives for a while.  A cycle made due by a call's
latency that declined so once left the next cycle armed for the C entries with those rows
out, so their drives stood still for it (a homing that ended later).  Compared exactly with
every cycle run one by one, and with the readers' Python functions; the session must have
met such a declined due cycle, and no cycle may stand armed while the bank has rows out."""

from __future__ import annotations

from ctypes import byref, c_double, c_uint32, c_ushort
from typing import Any

import pytest

from gtecat import gt
from gtecat.controller.core import Controller
from gtecat.controller.epoch import EPOCH
from gtecat.drives.machine import AxisMachine, MachineDescription
from tests.conftest import LONG
from tests.gtecat.controller.test_bank import HAS_CC

from .conftest import bring_up

pytestmark = pytest.mark.skipif(not HAS_CC, reason="no C compiler (cc, gcc or clang) on PATH")

AXES = (1, 2)
#: switches and index pulses a little apart per axis, so that their events fall in
#: different cycles and polls
MACHINE = MachineDescription(
    {
        a: AxisMachine(
            home_switch=((4_000 + 4 * a, 4_400 + 4 * a),),
            positive_limit=7_000 + 4 * a,
            negative_limit=-7_000 - 4 * a,
            counts_per_rev=1_000,
            index_offset=150 + 4 * a,
        )
        for a in AXES
    }
)
#: the ways a session runs its cycles: the default ones; the same with waits the general
#: way (``Controller.QUICK_WAIT`` off); the readers' Python functions (``GTECAT_CENTRY=0``'s
#: public ones); every cycle the general way, one by one, nothing armed (the reference)
QUICK, SLOW_WAITS, PYTHON, ONE_BY_ONE = "quick", "slow_waits", "python", "one_by_one"
#: calls before the homings start (50 us of latency each): the polls' phase against the
#: cycles, so that some homing event falls in a cycle a call makes due.  The default run
#: keeps phase 4, where every way meets such a cycle (a due cycle left armed after its
#: cycle declined fails it, as it fails each phase alone); GTECAT_LONG=1 runs all three
PHASES = (0, 4, 8) if LONG else (4,)


def _one_by_one(mp: pytest.MonkeyPatch) -> None:
    mp.setattr(Controller, "run_cycles", lambda self, n: 0)
    mp.setattr(Controller, "due_cycle", lambda self, pending: False)
    mp.setattr(Controller, "arm_quick", lambda self, k: None)
    mp.setattr(Controller, "QUICK_WAIT", False)


def _counting_declines(mp: pytest.MonkeyPatch) -> list[int]:
    """[0]: the due cycles (:meth:`Controller.due_cycle`) after which the bank had rows out
    (the kernel declined the cycle, the general way gave rows back)."""
    seen = [0]
    due = Controller.due_cycle

    def counted(self: Controller, pending: int) -> bool:
        ran = due(self, pending)
        bank = self.bank
        if ran and bank is not None and bank.n_alive != bank.n:
            seen[0] += 1
        return ran

    mp.setattr(Controller, "due_cycle", counted)
    return seen


def _session(way: str, phase: int, mp: pytest.MonkeyPatch) -> tuple[list[Any], int]:
    """What every poll read, and the declined due cycles (:func:`_counting_declines`);
    ``phase``: calls before the homings start."""
    if way == ONE_BY_ONE:
        _one_by_one(mp)
    if way == SLOW_WAITS:
        mp.setattr(Controller, "QUICK_WAIT", False)
    declined = _counting_declines(mp)

    def fn(name: str) -> Any:
        f = getattr(gt, name)
        return getattr(f, "python", f) if way == PYTHON else f

    status, enc, clock = fn("GT_GetEcatHomingStatus"), fn("GT_GetEncPos"), fn("GT_GetClock")
    bring_up(machine=MACHINE, clock="auto")
    ctl = gt.GTE_Controller()
    for a in AXES:
        assert gt.GT_AxisOn(a) == 0, gt.GTE_GetLastError()
    gt.GTE_Wait(50)
    st, pos, clk = c_ushort(), c_double(), c_uint32()
    for a in AXES:
        assert gt.GT_SetHomingMode(a, 6) == 0, gt.GTE_GetLastError()
        assert gt.GT_SetEcatHomingPrm(a, 2, 20_000, 2_000, 150_000, 0, 0) == 0
    for _ in range(phase):
        gt.GT_GetClock(byref(clk), None)
    for a in AXES:
        assert gt.GT_StartEcatHoming(a) == 0, gt.GTE_GetLastError()
    pending = set(AXES)
    seen: list[Any] = []
    q = ctl.clock.quick
    while pending and len(seen) < 3_000:
        gt.GTE_Wait(1)
        row: list[Any] = [clock(byref(clk), None), clk.value]
        for a in sorted(pending):
            row += [status(a, byref(st)), st.value, enc(a, byref(pos)), pos.value]
            if st.value & 1:
                pending.discard(a)
        seen.append(row)
        bank = ctl.bank
        # an armed cycle stands only while the bank runs every axis
        assert not (q[4] and q[4] == EPOCH.n and bank.n_alive != bank.n), len(seen)
    assert not pending, seen[-1]
    gt.GT_Close()
    return seen, declined[0]


def test_drive_homing_polled_is_the_same_in_every_way(monkeypatch: pytest.MonkeyPatch) -> None:
    declined = dict.fromkeys((QUICK, SLOW_WAITS, PYTHON), 0)
    for phase in PHASES:
        with monkeypatch.context() as mp:
            reference, _ = _session(ONE_BY_ONE, phase, mp)
        for way in declined:
            with monkeypatch.context() as mp:
                got, n = _session(way, phase, mp)
            declined[way] += n
            assert len(got) == len(reference), (way, phase)
            for k, (a, b) in enumerate(zip(reference, got, strict=True)):
                assert a == b, f"{way}, phase {phase}: poll {k}"
    # the case this test is for: in each way some due cycle declined
    assert all(declined.values()), declined
