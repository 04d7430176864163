"""PVT motion in the axis bank against the scalar reference: one GT program, cycle by cycle,
with ``bank="on"`` and ``bank="off"`` (the harness of ``test_bank_modes.py``: every axis's
GT_GetSts word, planned and encoder positions and speeds, the whole GT raw image, and at the
end the drives' mechanics, all compared with ``==``).

The program runs every table form (GT_PvtTable, GT_PvtTableEx, GT_PvtTableComplete), tables
starting at a negative, a zero and an odd time, one a few cycles long (passes ending inside
a cycle), one whose end falls a rounding error before a cycle's multiple, loop counts 0
(endless), 1, 2, 3, 5 and 7 (passes ending inside a table of the bank's, the last pass's
end), starts at different cycles, a table rewritten while axes run it, a PVT axis as a Gear
master, a soft limit crossed, smooth and abrupt stops, GT_PvtStatus and GT_GetPvtLoop in
the middle of tables (read from the bank, the axes kept there), an axis started again on
another table after its end.
"""

from __future__ import annotations

from ctypes import byref, c_double, c_long, c_short
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.controller import bank_pvt
from gtecat.controller.motion.pvt import PvtPlanner, PvtSegment
from tests.gtecat.controller.test_bank import AXES, _bring_up, _machine_file, _ok
from tests.gtecat.controller.test_bank_modes import Script, _bit, _gear, _run, reference


def _arr(*v: float):
    return (c_double * len(v))(*v)


def _tables() -> None:
    _ok(gt.GT_PvtTable(1, 3, _arr(0, 37.5, 81.3), _arr(0, 4000, 1500), _arr(0, 60, 0)), "t1")
    t, p = _arr(14.21, 30, 52.7, 71.21), _arr(0, 800, 2600, 3000)
    _ok(gt.GT_PvtTableEx(2, 4, t, p, _arr(5, 40, 20, 0), _arr(40, 25, 0, 0)), "t2")
    a, b, c = _arr(0, 0, 0, 0, 0), _arr(0, 0, 0, 0, 0), _arr(0, 0, 0, 0, 0)
    t, p = _arr(0, 10, 25, 33, 50), _arr(0, 300, -200, 100, 900)
    _ok(gt.GT_PvtTableComplete(3, 5, t, p, a, b, c, 2.0, -3.0), "t3")
    _ok(gt.GT_PvtTable(4, 3, _arr(0, 1.3, 2.6), _arr(0, 5, 9), _arr(1, 4, 2)), "t4")
    _ok(gt.GT_PvtTable(5, 3, _arr(-20, 0, 15.5), _arr(100, -400, 250), _arr(0, -10, 0)), "t5")


def _pvt(a: int, table: int, loop: int) -> None:
    _ok(gt.GT_PrfPvt(a), "PrfPvt")
    _ok(gt.GT_PvtTableSelect(a, table), "PvtTableSelect")
    _ok(gt.GT_SetPvtLoop(a, loop), "SetPvtLoop")


#: axis -> (table, loop); the axes not here: 7 stays in Trap, 9 is geared to 1
PLAN = {1: (1, 0), 2: (2, 3), 3: (3, 0), 4: (4, 0), 5: (5, 2), 6: (1, 1), 8: (3, 5)}
LATER = {10: (2, 0), 11: (1, 7)}
LAST = {12: (5, 0)}


def _setup() -> object:
    _tables()
    for a, (table, loop) in {**PLAN, **LATER, **LAST}.items():
        _pvt(a, table, loop)
    _gear(9, 1, gt.GEAR_MASTER_PROFILE, (2, 1, 0))
    gt.GT_SetSoftLimit(3, 700, -(1 << 30))  # crossed near the end of table 3's pass
    return (gt.GT_PvtStart(_bit(*PLAN)), gt.GT_GearStart(_bit(9)))


def _status() -> tuple:
    ids, times = c_short(), (c_double * AXES)()
    rc = gt.GT_PvtStatus(1, byref(ids), times, AXES)
    return (rc, ids.value, tuple(times))


def _loops() -> tuple:
    out = []
    for a in range(1, AXES + 1):
        done, loop = c_long(), c_long()
        out.append((gt.GT_GetPvtLoop(a, byref(done), byref(loop)), done.value, loop.value))
    return tuple(out)


#: the samples the last bank="on" run's compiled PVT fill wrote
COMPILED = [0]


def _compiled() -> None:
    bank = gt.GTE_Controller().bank
    pf = bank.__dict__.get("_pvt_fill") if bank is not None else None
    COMPILED[0] = pf.samples if pf else 0


PVT: Script = [
    (0, _setup),
    (13, lambda: gt.GT_PvtStart(_bit(*LATER))),
    (28, lambda: gt.GT_PvtStart(_bit(*LAST))),
    # table 1 rewritten while axes 1, 6 and 11 run it: their next start takes it
    (29, lambda: gt.GT_PvtTable(1, 3, _arr(0, 20, 45), _arr(0, -900, 300), _arr(0, -5, 0))),
    (19, lambda: gt.GT_Stop(_bit(5), 0)),  # smooth
    (6, lambda: gt.GT_Stop(_bit(8), _bit(8))),  # abrupt
    (23, _status),  # every PVT axis back to the scalar objects, mid-table
    (17, _loops),
    (31, lambda: (gt.GT_ClrSts(1, AXES), gt.GT_PvtTableSelect(6, 2), gt.GT_PvtStart(_bit(6)))),
    (45, lambda: (gt.GT_PvtTableSelect(5, 4), gt.GT_PvtStart(_bit(5)))),
    (60, _status),
    (40, _loops),
    (0, _compiled),
]


@pytest.fixture(scope="module")
def machine(tmp_path_factory: pytest.TempPathFactory) -> str:
    return _machine_file(Path(tmp_path_factory.mktemp("pvt")))


@pytest.mark.parametrize("chunked", [False, True], ids=["every-cycle", "chunked"])
def test_pvt_in_the_bank_matches_the_scalar_path(machine, chunked) -> None:
    bank_pvt.library()  # (built before the bank takes its first table)
    ref, none = reference(_run, PVT, machine, chunked)
    assert none == 0
    COMPILED[0] = 0
    got, samples = _run(PVT, machine, "on", chunked)
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"step {k}: the bank and the scalar path differ"
    assert samples >= 1500, "the bank hardly ran PVT"
    if bank_pvt.library()[0] is not None:
        assert COMPILED[0] >= 1000, "the compiled PVT fill hardly ran"


@pytest.mark.sample(1)
def test_pvt_in_the_numpy_bank_matches_the_scalar_path(machine) -> None:
    """The same without the compiled cycle (no C compiler): the planners' own steps."""
    ref, _ = reference(_run, PVT, machine, True)
    got, samples = _run(PVT, machine, "on", True, kernel="numpy")
    assert got == ref
    assert samples >= 1500


def test_pvt_status_and_loop_reads_keep_the_axes_in_the_bank(machine) -> None:
    """GT_PvtStatus and GT_GetPvtLoop answer from the bank (the values: the test above):
    polling them gave every PVT axis back and took it again (64 axes polled every 20 ms:
    2x real time per CPU second)."""
    bank_pvt.library()
    _bring_up(machine, "on")
    try:
        _setup()
        gt.GTE_Wait(45)
        bank = gt.GTE_Controller().bank
        for _ in range(3):
            before = (bank.releases, bank.n_alive)
            _status()
            _loops()
            assert (bank.releases, bank.n_alive) == before
            gt.GTE_Wait(7)
    finally:
        gt.GT_Close()


def test_a_sample_a_rounding_error_past_the_table_is_its_last_segment() -> None:
    """14.21 + 57 * 1.0 lands 1.4e-14 ms past a table ending at 71.21: the planner samples
    the last segment there (it ran off the table's end before) and ends at the next cycle."""
    pl = PvtPlanner(1.0)
    segs = (PvtSegment(14.21, 40.0, 0.0, 100.0, 0.0, 1.0), PvtSegment(40.0, 71.21, 100, 200, 1, 0))
    pl.start(1, segs)
    for _ in range(57):
        pos, _, _ = pl.step()
    assert abs(pos - 200.0) < 1e-9 and not pl.done
    pl.step()
    assert pl.done and pl.pos == 200.0
