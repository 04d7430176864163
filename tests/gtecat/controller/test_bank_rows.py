"""Many cycles in one call of the compiled kernel, row by row, against the scalar reference.

On a bus of CSP drives alone every axis stays in the bank, so a long ``GTE_Wait`` runs its
cycles many at a time (``bank_kernel_run``): each row runs all of them on its own and the call
commits as many as every row could run.  The programs make rows stop at different cycles of
one call - moves that end, a soft limit and a limit switch met in the middle of a wait - after
tables refilled at different cycles (the moves start a few cycles apart), so rows that ran
further are put back and run again; bands and following-error windows check the band and
the checks of every cycle, a Jog runs among them and a switched-off axis rests among them.
Sampled at the end of each wait, compared with ``==``.
"""

from __future__ import annotations

import os
import shutil
from ctypes import byref, c_double, c_long, c_ubyte

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gtecat import gt
from tests.conftest import examples
from tests.gtecat.controller.test_bank import _ok, open_bus
from tools.gen_axes_eni import write_axes_eni

AXES = 6
HAS_CC = bool(os.environ.get("CC") or any(shutil.which(c) for c in ("cc", "gcc", "clang")))


@pytest.fixture(scope="module")
def bus(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, str]:
    tmp = tmp_path_factory.mktemp("rows")
    eni = write_axes_eni(AXES, tmp / "bus.eni")
    machine = tmp / "machine.toml"
    machine.write_text(
        "[axis.2]\npositive_limit = 30000\nnegative_limit = -30000\n"
        "[axis.4]\nfollowing_error_window = 40\n"
    )
    return str(eni), str(machine)


def _open(bus: tuple[str, str], bank: str) -> None:
    open_bus(bus[0], bus[1], bank)
    for a in range(1, AXES + 1):
        _ok(gt.GT_AxisOn(a), f"axis on {a}")
        _ok(gt.GT_PrfTrap(a), "trap")


def _sample(size: int) -> tuple:
    sts, prf, enc = (c_long * AXES)(), (c_double * AXES)(), (c_double * AXES)()
    vel, raw = (c_double * AXES)(), (c_ubyte * size)()
    gt.GT_GetSts(1, sts, AXES)
    gt.GT_GetPrfPos(1, prf, AXES)
    gt.GT_GetEncPos(1, enc, AXES)
    gt.GT_GetEncVel(1, vel, AXES)
    gt.GT_GetEcatRawData(0, size, raw)
    return tuple(sts), tuple(prf), tuple(enc), tuple(vel), bytes(raw)


def _act(action: tuple) -> int:
    kind, axis = action[0], action[1]
    if kind == "move":
        _, _, target, vel, acc, smooth = action
        prm = gt.TTrapPrm()
        prm.acc, prm.dec, prm.velStart, prm.smoothTime = acc, acc, 0.0, smooth
        gt.GT_SetTrapPrm(axis, byref(prm))
        gt.GT_SetPos(axis, target)
        gt.GT_SetVel(axis, vel)
        return gt.GT_Update(1 << (axis - 1))
    if kind == "jog":
        _, _, vel, acc, smooth = action
        gt.GT_PrfJog(axis)
        prm = gt.TJogPrm()
        prm.acc, prm.dec, prm.smooth = acc, acc, smooth
        gt.GT_SetJogPrm(axis, byref(prm))
        gt.GT_SetVel(axis, vel)
        return gt.GT_Update(1 << (axis - 1))
    if kind == "trap":
        return gt.GT_PrfTrap(axis)
    if kind == "soft":
        return gt.GT_SetSoftLimit(axis, action[2], -1_000_000)
    if kind == "band":
        return gt.GT_SetAxisBand(axis, action[2], action[3])
    if kind == "off":
        return gt.GT_AxisOff(axis)
    if kind == "on":
        return gt.GT_AxisOn(axis)
    if kind == "clear":
        return gt.GT_ClrSts(1, AXES)
    if kind == "stop":  # GT_Stop(mask, option): smooth (0) or abrupt (the axis's bit)
        mask = 1 << (axis - 1)
        return gt.GT_Stop(mask, mask if action[2] else 0)
    raise AssertionError(kind)


def _run(bus: tuple[str, str], program: list[tuple[int, tuple]], bank: str) -> tuple[list, int]:
    """(the samples after each wait, the cycles the kernel ran many at a time)"""
    old = os.environ.get("GTECAT_BANK_KERNEL")
    os.environ["GTECAT_BANK_KERNEL"] = "c"
    try:
        _open(bus, bank)
    finally:
        if old is None:
            del os.environ["GTECAT_BANK_KERNEL"]
        else:
            os.environ["GTECAT_BANK_KERNEL"] = old
    ctl = gt.GTE_Controller()
    size = ctl.layout.gt_raw_bytes
    out = []
    try:
        for wait, action in program:
            out.append(_act(action))
            gt.GTE_Wait(wait)
            out.append(_sample(size))
        many = ctl.bank.many_cycles if ctl.bank is not None else 0
        if ctl.bank is not None and ctl.bank.kernel is None:
            if not HAS_CC:
                pytest.skip(
                    "no C compiler (cc, gcc or clang): the bank's compiled cycle is not built"
                )
            raise AssertionError(
                f"the bank's compiled cycle did not build: {ctl.bank.kernel_reason}"
            )
    finally:
        gt.GT_Close()
    return out, many


def _check(bus: tuple[str, str], program: list[tuple[int, tuple]]) -> int:
    ref, _ = _run(bus, program, "off")
    got, many = _run(bus, program, "on")
    for k, (a, b) in enumerate(zip(ref, got, strict=True)):
        assert a == b, f"step {k}: the bank and the scalar path differ"
    return many


def test_rows_stopping_at_different_cycles_of_one_call(bus: tuple[str, str]) -> None:
    """Staggered starts (tables refilled at different cycles), moves ending inside a wait,
    axis 3 meeting its soft limit and axis 2 its limit switch in the middle of long waits."""
    program = [
        (3, ("move", 1, 9_000, 20.0, 0.5, 25)),
        (5, ("move", 2, 45_000, 30.0, 0.8, 5)),  # its +30000 limit switch stops it
        (2, ("move", 3, -30_000, 25.0, 0.6, 0)),
        (7, ("soft", 3, 1_000)),
        (4, ("move", 4, 7_777, 15.0, 0.4, 50)),
        (1, ("band", 5, 8, 3)),
        (6, ("move", 5, -5_000, 10.0, 0.3, 25)),
        (9, ("jog", 6, -12.0, 0.3, 0.5)),
        (400, ("band", 1, 5, 4)),
        (300, ("off", 5)),  # switched off: its rows rest while the others run
        (3, ("move", 1, -4_000, 40.0, 2.0, 0)),
        (300, ("jog", 6, 7.5, 0.2, 0.9)),
        (2, ("on", 5)),
        (2, ("move", 3, 20_000, 25.0, 0.6, 25)),  # runs into its soft limit at 1000
        (900, ("clear", 0)),
        (300, ("clear", 0)),
    ]
    assert _check(bus, program) > 800  # most of the waits ran many cycles per kernel call


@pytest.mark.parametrize(
    ("last", "least"),
    # (the waits before the last run about 390 cycles many at a time)
    [(600, 900), pytest.param(3000, 2500, marks=pytest.mark.long("a last wait of 3 s"))],
)
def test_rows_back_in_the_bank_after_a_stop(bus: tuple[str, str], last: int, least: int) -> None:
    """GT_Stop mid-move, smooth and abrupt (Trap and Jog): once the stop ramp has ended the
    axes stand, and the long wait after it runs in the bank again (a planner at rest is no
    longer stopping), with the same answers as the scalar path."""
    program = [
        (2, ("move", 1, 30_000, 20.0, 0.5, 25)),
        (2, ("move", 3, -30_000, 25.0, 0.6, 0)),
        (2, ("jog", 6, -12.0, 0.3, 0.5)),
        (200, ("stop", 1, False)),
        (2, ("stop", 3, True)),
        (200, ("stop", 6, False)),
        (last, ("clear", 0)),
    ]
    assert _check(bus, program) > least  # the last wait ran in the kernel, many at a time


axis = st.integers(1, AXES)
step = st.one_of(
    st.tuples(
        st.just("move"),
        axis,
        st.integers(-40_000, 40_000),
        st.floats(1.0, 40.0),
        st.floats(0.1, 3.0),
        st.sampled_from([0, 5, 25, 50]),
    ),
    st.tuples(
        st.just("jog"),
        axis,
        st.floats(-30.0, 30.0),
        st.floats(0.05, 2.0),
        st.sampled_from([0.0, 0.5, 0.9]),
    ),
    st.tuples(st.just("trap"), axis),
    st.tuples(st.just("soft"), axis, st.integers(0, 30_000)),
    st.tuples(st.just("band"), axis, st.integers(0, 30), st.integers(0, 10)),
    st.tuples(st.just("clear"), st.just(0)),
    st.tuples(st.just("stop"), axis, st.booleans()),
)


@pytest.mark.long
@settings(
    max_examples=examples(40, 12),
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(program=st.lists(st.tuples(st.integers(0, 400), step), min_size=1, max_size=12))
def test_programs_of_long_waits(bus: tuple[str, str], program) -> None:
    _check(bus, [*program, (300, ("clear", 0))])
