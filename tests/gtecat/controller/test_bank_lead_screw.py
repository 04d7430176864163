"""Lead-screw compensation in the axis bank against the scalar reference.

Axes with compensation tables (``GT_SetLeadScrewComp``) move in Trap and Jog across the
tables' points in both directions, beyond both ends, reverse, have the compensation switched
on and off while they move, get new tables, stop, are switched off and on, and have their
planned position set; one axis has a table and the compensation off (the direction is still
followed), one has none.  Every program runs three ways - the scalar path
(``GT_Open(bank="off")``), the bank with its compiled cycle, the bank on numpy - and the
planned and encoder positions, the encoder speeds, the status words and the whole raw image
(607Ah carries the correction) after every wait are compared with ``==``.  Waits of one
cycle and of hundreds (many cycles in one kernel call, row by row) alternate.
"""

from __future__ import annotations

import os
from ctypes import c_long
from unittest import mock

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gtecat import gt
from tests.conftest import LONG, examples
from tests.gtecat.controller.test_bank import HAS_CC, _ok
from tests.gtecat.controller.test_bank_rows import AXES, _sample
from tests.gtecat.controller.test_bank_rows import _act as _rows_act
from tests.gtecat.controller.test_bank_rows import _open as rows_open
from tests.gtecat.controller.test_bank_rows import step as rows_step
from tools.gen_axes_eni import write_axes_eni


@pytest.fixture(scope="module")
def bus(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, str]:
    tmp = tmp_path_factory.mktemp("screw")
    eni = write_axes_eni(AXES, tmp / "bus.eni")
    machine = tmp / "machine.toml"
    machine.write_text("[axis.6]\npositive_limit = 60000\nnegative_limit = -60000\n")
    return str(eni), str(machine)


def _tables(n: int, seed: int) -> tuple[object, object]:
    pos = [(-1) ** k * (5 * k + seed) for k in range(n)]
    neg = [3 * k - seed + (k * seed) % 7 for k in range(n)]
    return (c_long * n)(*pos), (c_long * n)(*neg)


def _act(action: tuple) -> int:
    kind, axis = action[0], action[1]
    if kind == "screw":  # n points from start over length pulses
        _, _, n, start, length, seed = action
        pos, neg = _tables(n, seed)
        return gt.GT_SetLeadScrewComp(axis, n, start, length, pos, neg)
    if kind == "enable":
        return gt.GT_EnableLeadScrewComp(axis, action[2])
    if kind == "move":  # (from any mode: Trap first)
        gt.GT_PrfTrap(axis)
    if kind in ("move", "jog", "trap", "soft", "band", "stop", "off", "on", "clear"):
        return _rows_act(action)
    if kind == "prfpos":
        return gt.GT_SetPrfPos(axis, action[2])
    if kind == "wait":
        return 0
    if kind == "home":  # drive homing (mode 6) with a method
        _ok(gt.GT_SetHomingMode(axis, 6), "homing mode")
        _ok(gt.GT_SetEcatHomingPrm(axis, action[2], 30_000, 8_000, 800_000, 0, 0), "prm")
        return gt.GT_StartEcatHoming(axis)
    if kind == "csp":
        _ok(gt.GT_SetHomingMode(axis, 8), "csp")
        return gt.GT_PrfTrap(axis)
    if kind == "gear":  # a slave of its master's planned position, ratio 2:1
        _ok(gt.GT_PrfGear(axis, 0), "gear")
        _ok(gt.GT_SetGearMaster(axis, action[2], gt.GEAR_MASTER_PROFILE, 0), "master")
        _ok(gt.GT_SetGearRatio(axis, 2, 1, 400), "ratio")
        return gt.GT_GearStart(1 << (axis - 1))
    if kind == "pt":  # a static FIFO looping 0 -> 8000 -> 0 in 30 segments of 15 ms
        _ok(gt.GT_PrfPt(axis, gt.PT_MODE_STATIC), "pt")
        _ok(gt.GT_PtClear(axis, 0), "clear")
        _ok(gt.GT_SetPtLoop(axis, 0), "loop")
        for k in range(1, 31):
            pos = 8000.0 * (k if k <= 15 else 30 - k) / 15
            _ok(gt.GT_PtData(axis, pos, 15 * k, gt.PT_SEGMENT_NORMAL, 0), "data")
        return gt.GT_PtStart(1 << (axis - 1), 0)
    raise AssertionError(kind)


#: every axis but the last has a table (points every 2000 pulses from -10000 to 10000, the
#: fifth axis's 7 points over 9000 from -3000), the first four with the compensation on
SETUP = [
    *[(0, ("screw", a, 11, -10_000, 20_000, a)) for a in range(1, 5)],
    (0, ("screw", 5, 7, -3_000, 9_000, 5)),
    *[(0, ("enable", a, 1)) for a in range(1, 5)],
]


def _run(bus: tuple[str, str], program: list[tuple[int, tuple]], bank: str, kernel: str):
    """(the samples after each wait, the screw axes' share of the waits' samples that found
    them in the bank, the cycles the kernel ran many at a time)"""
    with mock.patch.dict(os.environ, {"GTECAT_BANK_KERNEL": kernel}):
        rows_open(bus, bank)
    ctl = gt.GTE_Controller()
    size = ctl.layout.gt_raw_bytes
    out: list = []
    held = seen = 0
    try:
        gt.GTE_Wait(5)
        for wait, action in [*SETUP, *program]:
            out.append(_act(action))
            gt.GTE_Wait(wait)
            b = ctl.bank
            if b is not None and b.n and wait:
                rows = [b._row_of[id(ctl.axes[a])] for a in range(1, 6)]
                held += int(b.alive[rows].sum())
                seen += len(rows)
            out.append(_sample(size))
        b = ctl.bank
        many = b.many_cycles if b is not None else 0
        if bank == "on" and kernel == "c" and b is not None and b.kernel is None:
            if not HAS_CC:
                pytest.skip("no C compiler (cc, gcc or clang): the compiled cycle is not built")
            raise AssertionError(f"the bank's compiled cycle did not build: {b.kernel_reason}")
    finally:
        gt.GT_Close()
    return out, held / max(seen, 1), many


def _check(
    bus: tuple[str, str],
    program: list[tuple[int, tuple]],
    kernels: tuple[str, ...] = ("c", "numpy"),
) -> tuple[dict, int]:
    """({kernel: the screw axes' share in the bank}, the cycles run many at a time)"""
    ref, _, _ = _run(bus, program, "off", "c")
    share, many = {}, 0
    for kernel in kernels:
        got, share[kernel], ran = _run(bus, program, "on", kernel)
        for k, (a, b) in enumerate(zip(ref, got, strict=True)):
            assert a == b, f"{kernel}: step {k}: the bank and the scalar path differ"
        many = ran if kernel == "c" else many
    return share, many


def test_compensated_axes_across_the_tables_both_ways(bus: tuple[str, str]) -> None:
    """Moves over the tables' points and beyond both ends, reversals in mid move, the
    compensation switched off and on while moving, a new table, a stop, an axis switched off
    and on, a planned position set: bit-equal, and the compensated axes ran in the bank."""
    program = [
        (3, ("move", 1, 14_000, 20.0, 0.5, 25)),  # beyond the table's positive end
        (2, ("move", 2, -14_000, 25.0, 0.6, 0)),  # beyond its negative end
        (1, ("move", 3, 3_333, 12.0, 0.4, 50)),
        (1, ("jog", 4, -13.0, 0.3, 0.5)),
        (4, ("move", 5, 7_000, 9.0, 0.3, 5)),
        (1, ("move", 6, 5_000, 30.0, 1.0, 0)),
        (175, ("enable", 1, 0)),  # off while moving: 607Ah jumps back by the correction
        (1, ("enable", 1, 1)),
        (1, ("enable", 1, 0)),
        (200, ("enable", 1, 1)),
        (150, ("move", 3, -6_500, 18.0, 0.7, 25)),  # a reversal in mid move
        (300, ("jog", 4, 16.0, 0.2, 0.9)),  # a jog turning round
        (450, ("off", 2)),
        (40, ("on", 2)),
        (3, ("move", 2, 1_999, 30.0, 0.5, 0)),
        (200, ("stop", 3, False)),
        (150, ("move", 5, -4_000, 25.0, 1.0, 0)),
        (350, ("stop", 4, True)),
        (100, ("prfpos", 4, 20_000)),  # a set planned position turns the direction
        (5, ("screw", 4, 5, 19_000, 4_000, 9)),  # a new table while standing
        (2, ("enable", 5, 1)),
        (2, ("move", 4, 17_000, 20.0, 0.5, 0)),
        (750, ("move", 1, -12_000, 40.0, 2.0, 25)),
        (600, ("enable", 5, 0)),
        (750, ("clear", 0)),
        # moves that end within short waits (each cycle a call of its own), all axes on and
        # then with one switched off: the direction they end in is the one they stand in
        (1, ("move", 3, -6_800, 30.0, 2.0, 0)),
        (1, ("move", 5, -3_900, 30.0, 2.0, 0)),
        *[(3, ("wait", 0))] * 20,
        (1, ("move", 3, -6_300, 30.0, 2.0, 0)),
        *[(3, ("wait", 0))] * 20,
        (2, ("off", 6)),
        (1, ("move", 3, -6_700, 30.0, 2.0, 0)),
        *[(3, ("wait", 0))] * 20,
        (150, ("on", 6)),
    ]
    share, many = _check(bus, program)
    assert min(share.values()) > 0.7  # the compensated axes were in the bank at most samples
    assert many > 2_500  # the long waits ran many cycles per kernel call


def test_compensated_axes_in_gear_and_pt(bus: tuple[str, str]) -> None:
    """A Gear slave and its Trap master, a PT axis looping over a table's points, each with
    the compensation on (stepped a table ahead by the bank), switched off and on."""
    program = [
        (1, ("move", 1, 9_000, 20.0, 0.5, 25)),
        (1, ("gear", 2, 1)),
        (1, ("pt", 3, 0)),
        (1, ("pt", 5, 0)),
        (700, ("enable", 2, 0)),
        (3, ("enable", 2, 1)),
        (400, ("enable", 3, 0)),
        (200, ("enable", 3, 1)),
        (600, ("move", 1, -9_000, 30.0, 1.0, 0)),
        *[(2, ("wait", 0))] * 10,
        (700, ("stop", 3, False)),
        (400, ("clear", 0)),
    ]
    # (the numpy cycle with GTECAT_LONG=1: the default run's numpy runs are the tables test
    # above, the screw in the numpy cycle, and test_bank_modes', Gear and PT tables by Python)
    share, _ = _check(bus, program, ("c", "numpy") if LONG else ("c",))
    assert min(share.values()) > 0.7


@pytest.fixture(scope="module")
def homing_bus(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, str]:
    tmp = tmp_path_factory.mktemp("screw_homing")
    eni = write_axes_eni(AXES, tmp / "bus.eni")
    machine = tmp / "machine.toml"
    machine.write_text(
        "[axis.1]\nnegative_limit = -7000\n"
        "[axis.2]\nnegative_limit = -6000\nindex_offset = 300\ncounts_per_rev = 4000\n"
        "[axis.3]\nhome_switch = [[5000, 900000]]\n"
        "[axis.5]\nhome_switch = [[4000, 6000]]\nnegative_limit = -5000\n"
    )
    return str(eni), str(machine)


def test_compensated_axes_homed_by_their_drives(homing_bus: tuple[str, str]) -> None:
    """Drive homings (limit switch, limit and index pulse, home switch, current position,
    a reversal on a limit) of axes with the compensation on or off, sampled every cycle,
    then back in CSP and moving over the tables: the homing rows follow the direction the
    way the scalar hook sees it (a cycle behind the drive)."""
    program = [
        (1, ("home", 1, 17)),
        (1, ("home", 2, 1)),
        (1, ("home", 3, 19)),
        (1, ("home", 4, 35)),
        (1, ("home", 5, 11)),
        (1, ("move", 6, -8_000, 20.0, 0.5, 0)),
        *[(1, ("wait", 0))] * 700,
        (100, ("wait", 0)),
        *[(1, ("csp", a)) for a in range(1, 6)],
        *[(1, ("move", a, 3_000 * a - 7_000, 20.0, 0.5, 0)) for a in range(1, 6)],
        (600, ("wait", 0)),
    ]
    share, _ = _check(homing_bus, program)
    assert share["c"] > 0.7  # (the numpy cycle runs no homing rows)


#: test_bank_rows' steps (moves, jogs, soft limits, bands, stops...) and the compensation
#: switched on and off
step = st.one_of(rows_step, st.tuples(st.just("enable"), st.integers(1, 5), st.integers(0, 1)))


@pytest.mark.long
@settings(
    max_examples=examples(30, 6),
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(program=st.lists(st.tuples(st.integers(0, 400), step), min_size=1, max_size=10))
def test_programs(bus: tuple[str, str], program) -> None:
    _check(bus, [*program, (300, ("clear", 0))])


def test_the_numpy_values_are_the_scalar_values_bit_for_bit() -> None:
    """screw_values (the numpy cycle's) against LeadScrew.value at points on, between and
    beyond the table's points, in both directions."""
    import random
    from types import SimpleNamespace

    import numpy as np

    from gtecat.controller.lead_screw import LeadScrew, set_lead_screw
    from gtecat.controller.lead_screw_bank import screw_arrays, screw_load, screw_values

    class Axis:  # what a screw hangs on: the hooks
        def __init__(self) -> None:
            self.pre_hooks: list = []

    rnd = random.Random(7)
    screws = [
        LeadScrew(-10_000.0, 20_000.0, tuple(map(float, p)), tuple(map(float, q)))
        for p, q in (_tables(11, 3), _tables(2, 1))
    ] + [LeadScrew(0.5, 333.3, (1.0, -7.0, 123.0, 4.0), (0.0, 2.0, 3.0, -9.0))]
    bank = SimpleNamespace(kernel=None)
    screw_arrays(bank, len(screws))
    axes = [Axis() for _ in screws]
    for r, (ax, s) in enumerate(zip(axes, screws, strict=True)):
        set_lead_screw(ax, s)
        screw_load(bank, r, ax)
    for r, s in enumerate(screws):
        for _ in range(300):
            pos = rnd.choice([rnd.uniform(-12_000, 12_000), rnd.uniform(-1, 340), 0.5, -10_000.0])
            d = rnd.choice([1, -1])
            got = screw_values(bank, np.array([r]), np.array([pos]), np.array([d]))[0]
            assert got == s.value(pos, d), (r, pos, d)
