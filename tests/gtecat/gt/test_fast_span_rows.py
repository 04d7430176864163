"""A span of a reader whose value is a link or a bit of a banked axis's value (the readers
of ``fast.BANK_ROWS``, and the encoder's speed: ``fast.SPAN_ROWS``): after each cycle of the
auto clock its C entry asks each row of the bank for its value alone, not every row's list;
what it writes is what the table path writes, cycle by cycle, while both axes move,
accelerate and stop.  The same of the spans of doubles of the bank's lists
(``fast.BANK_LISTS``: a run of rows in order is written from the bank's arrays in one
step) and of ``fast.QUICK_ROWS``' quicker rows, and of their own ways while an axis jogs
(neither applies).  A span of status words stands across the cycles that keep every
flag."""

from __future__ import annotations

import ctypes
from collections.abc import Iterator
from contextlib import contextmanager
from ctypes import byref, c_double, c_long
from typing import Any

from gtecat import gt
from gtecat.gt import fast

from .conftest import bring_up, trap_move

#: the readers of the spans read: the rows' and the doubles of the bank's lists
_SPANS = sorted(
    fast.BANK_ROWS | fast.SPAN_ROWS | {k: v for k, v in fast.BANK_LISTS.items() if k != "GT_GetSts"}
)


def _moves_read(table: bool) -> tuple[list, int]:
    """Both axes' Trap moves, then axis 2's Jog, each cycle's spans read (``table``:
    through the table path): what was read, at which cycle, and how many of the reads found
    axis 1 a row of the bank."""
    bring_up(clock="auto")
    try:
        assert gt.GT_AxisOn(1) == 0 and gt.GT_AxisOn(2) == 0
        ctl = gt.GTE_Controller()
        s = c_long()
        for _ in range(400):  # (polls: the bank claims both axes)
            gt.GT_GetSts(1, byref(s))
        trap_move(1, 900, 12.0)
        trap_move(2, -600, 7.5)
        seen: list = []
        banked = 0
        for i in range(400):
            if i == 30:  # (a new target while axis 2 moves)
                assert gt.GT_SetPos(2, 600) == 0 and gt.GT_SetVel(2, 9.0) == 0
                assert gt.GT_Update(2) == 0
            if i == 320:  # (a jog: the bank's rows read their own ways)
                jog = gt.TJogPrm(acc=0.5, dec=0.5, smooth=0)
                assert gt.GT_PrfJog(2) == 0 and gt.GT_SetJogPrm(2, byref(jog)) == 0
                assert gt.GT_SetVel(2, 3.0) == 0 and gt.GT_Update(2) == 0
            banked += ctl.resources[1].bank is not None
            for name in _SPANS:
                fn = getattr(gt, name)
                fn = fn.slow if table else fn
                tp = c_long if name == "GT_GetPrfSts" else c_double
                arr = (tp * 4)()
                # &arr[1] and the array itself, 2 axes
                assert fn(1, byref(arr, ctypes.sizeof(tp)), 2, None) == 0
                assert fn(1, arr, 2) == 0
                seen.append((ctl.clock.cycles, name, bytes(arr)))
        assert gt.GT_Stop(2, 0) == 0
        gt.GTE_Wait(200)
        enc = (c_double * 2)()
        assert gt.GT_GetAxisEncVel(1, enc, 2) == 0
        seen.append(tuple(enc))
        return seen, banked
    finally:
        gt.GT_Close()


def test_row_spans_read_what_the_table_path_reads_cycle_by_cycle() -> None:
    """Each span read through the C entries, from the rows of the bank, and through the
    table path (which gives the axes back: the scalar objects' values), cycle by cycle."""
    rows, banked = _moves_read(False)
    table, _ = _moves_read(True)
    assert banked == 400  # (every read from the bank's rows)
    assert rows[-1] == (0.0, 0.0)  # (both moves ended)
    assert len({c for c, *_ in rows[:-1]}) > 200  # (cycle by cycle)
    assert rows == table


def _calls(pr: Any, names: tuple[str, ...]) -> int:
    """How often a profile ``pr`` saw gtecat.gt.fast's functions ``names`` called (those it
    compiles from source too: a reader's value function)."""
    import pstats

    stats = pstats.Stats(pr).stats.items()  # type: ignore[attr-defined]
    return sum(
        v[1]
        for (file, _, func), v in stats
        if func in names and (file.endswith("fast.py") or file.startswith("<gt fast "))
    )


@contextmanager
def _auto(general: bool, eni: str = "manual_fig5_2.eni", **options: Any) -> Iterator[Any]:
    """The bus ``eni`` brought up on the auto clock, its controller (``general``: with a
    watch hook that does nothing, so every cycle goes the general way), closed after."""
    bring_up(eni, clock="auto", **options)
    try:
        ctl = gt.GTE_Controller()
        if general:
            ctl.watch.append(lambda: None)
        yield ctl
    finally:
        gt.GT_Close()


class _Profiled:
    """A profile of the polls of a run's rounds, and the cycles they ran: every round on the
    quick way, the first alone on the general way (each of its cycles asks every value
    again, which one round shows as well as four; the profile triples that way's cost)."""

    def __init__(self, ctl: Any, general: bool) -> None:
        import cProfile

        self.ctl, self.general, self.cycles = ctl, general, 0
        self.pr = cProfile.Profile()

    @contextmanager
    def round(self, rnd: int) -> Iterator[None]:
        if rnd and self.general:
            yield
            return
        c0 = self.ctl.clock.cycles
        self.pr.enable()
        try:
            yield
        finally:
            self.pr.disable()
            self.cycles += self.ctl.clock.cycles - c0

    def asked(self) -> int:
        return _calls(self.pr, ("f", "value_gt", "value_gtn"))


def _status_polls(general: bool) -> tuple[list, int, int]:
    """Trap moves of both axes that start and end, every call a span of status words
    (``GT_GetSts``, ``GT_GetPrfSts``, with the clock) and each axis's word (``GT_GetSts``,
    ``GT_GetPrfSts``) polled on the auto clock; ``general``: a watch hook that does nothing,
    so every cycle goes the general way.  What was read, the cycles the profiled rounds ran
    (:class:`_Profiled`), and how often a value function was asked in them."""
    with _auto(general) as ctl:
        assert gt.GT_AxisOn(1) == 0 and gt.GT_AxisOn(2) == 0
        words, prf, one, two = (c_long * 2)(), (c_long * 2)(), c_long(), ctypes.c_int32()
        three, four = (c_long * 2)(), c_long()
        clk = ctypes.c_ulong()
        seen: list = []
        profiled = _Profiled(ctl, general)
        for rnd in range(4):
            trap_move(1 + rnd % 2, 300 * (rnd + 1) * (-1) ** rnd, 20.0)
            with profiled.round(rnd):
                for _ in range(2500):
                    assert gt.GT_GetSts(1, words, 2, byref(clk)) == 0
                    assert gt.GT_GetPrfSts(1, prf, 2) == 0
                    assert gt.GT_GetSts(1, byref(one)) == 0 and gt.GT_GetSts(2, two) == 0
                    assert gt.GTN_GetSts(1, 2, byref(three, ctypes.sizeof(c_long))) == 0
                    assert gt.GTN_GetPrfSts(1, 2, byref(four)) == 0
                    seen.append(
                        (clk.value, *words, *prf, one.value, two.value, three[1], four.value)
                    )
        return seen, profiled.cycles, profiled.asked()


def test_status_spans_stand_across_cycles_that_keep_every_flag() -> None:
    """A span of status words, and an axis's word of the bank's, is asked again only where
    a flag may have moved (a move's start or end, anything but a quick cycle booked in C):
    what every call reads is what it reads with every cycle the general way, while the axes
    start, move and stop."""
    quick, cycles, asked = _status_polls(False)
    general, general_cycles, asked_general = _status_polls(True)
    assert quick == general
    assert len({tuple(x[1:3]) for x in quick}) >= 3  # (each axis moving, and neither)
    assert asked_general > general_cycles  # (every cycle: each asked again)
    assert asked < cycles / 4  # (the words held across the quick cycles)


def _double_polls(
    general: bool, eni: str, first: int, count: int, cycle_ms: float | None
) -> tuple[list, int, int]:
    """Trap moves of the axes ``first``.. ``first + count - 1`` that start and end, every call
    a span of doubles of each reader whose span is a run of the bank's rows (the planned
    values, the encoder's and the axis's positions, and the values of fast.QUICK_SOURCES:
    the axis's planned speed and acceleration, the encoder's speed and acceleration)
    polled on the auto clock, each in one shape (a numpy array and a ctypes array, with and
    without the clock, C's ``&arr[1]``);
    ``general``: a watch hook that does nothing, so every cycle goes the general way.  What
    was read, the cycles the profiled rounds ran (:class:`_Profiled`), and how often a span's
    value function was asked in them."""
    import numpy as np

    with _auto(general, eni, cycle_ms=cycle_ms) as ctl:
        for a in range(first, first + count):
            assert gt.GT_AxisOn(a) == 0
        # the encoder's links of both branches (AffineLink.axis): a ratio of 3/7 and an
        # offset, an offset alone
        assert gt.GT_EncScale(first, 7, 3) == 0 and gt.GT_SetEncPos(first, 500) == 0
        assert gt.GT_SetEncPos(first + 1, 1234) == 0
        clk = ctypes.c_ulong()
        pos, acc = np.zeros(count + 1), (c_double * (count + 1))()
        vel, enc, apos = (c_double * count)(), (c_double * count)(), np.zeros(count)
        enc2 = (c_double * (count + 1))()
        rows = {name: np.zeros(count + 1) for name in fast.QUICK_SOURCES}
        one, two = c_double(), (c_double * 2)()
        seen: list = []
        profiled = _Profiled(ctl, general)
        for rnd in range(3):
            for k, a in enumerate(range(first, first + count)):  # (ends apart)
                trap_move(a, (200 + 90 * k) * (rnd + 1) * (-1) ** rnd, 15.0 + k)
            with profiled.round(rnd):
                for _ in range(300):
                    assert gt.GT_GetPrfPos(first, pos, count, byref(clk)) == 0
                    assert gt.GT_GetPrfVel(first, vel, count) == 0
                    assert gt.GT_GetPrfAcc(first, byref(acc, 8), count, clk) == 0
                    assert gt.GT_GetEncPos(first, enc, count) == 0
                    # (a second span of the same reader, read in turn: each kept in its lane)
                    assert gt.GT_GetEncPos(first + 1, byref(enc2, 8), count - 1) == 0
                    assert gt.GT_GetAxisPrfPos(first, apos, count) == 0
                    seen.append((clk.value, pos.tobytes(), bytes(vel), bytes(acc), bytes(enc)))
                    seen.append(bytes(enc2))
                    seen.append(apos.tobytes())
                    for name, arr in rows.items():
                        assert getattr(gt, name)(first, arr, count, clk) == 0
                        seen.append(arr.tobytes())
                    for name in fast.SCALAR_SOURCES:
                        # one axis's, into byref(x), and into &two[1] by the GTN_ twin (its entry
                        # keeps a span of its own: not this loop's spans')
                        assert getattr(gt, name)(first + 1, byref(one)) == 0
                        gtn = getattr(gt, name.replace("GT_", "GTN_"))
                        assert gtn(1, first, byref(two, 8)) == 0
                        seen.append((name, one.value, two[1]))
        return seen, profiled.cycles, profiled.asked()


def test_double_spans_gathered_after_cycles_booked_in_c() -> None:
    """A span of doubles that is a run of the bank's rows is gathered again in C from the
    bank's arrays after each cycle the entries book themselves (not asked in Python): what
    every call reads is what it reads with every cycle the general way, while the axes
    start, accelerate, move and stop; the whole bank (figure 5-2's two axes) and a run
    inside a larger one (axes 2-4 of twelve, cycles of 0.75 ms: the rates' divisions are not
    exact)."""
    for eni, first, count, ms in (
        ("manual_fig5_2.eni", 1, 2, None),
        ("twelve_axes.eni", 2, 3, 0.75),
    ):
        quick, cycles, asked = _double_polls(False, eni, first, count, ms)
        general, general_cycles, asked_general = _double_polls(True, eni, first, count, ms)
        assert quick == general
        assert len(set(quick)) > cycles / 2  # (values that move cycle by cycle)
        assert asked_general > general_cycles  # (every cycle: each span asked again)
        assert asked < cycles / 2  # (eleven spans: made again in C across the quick cycles)


def _mode_polls(general: bool) -> tuple[list, int, int]:
    """Both axes moving in Trap on the auto clock, their profile modes polled every call
    (``GT_GetPrfMode``: one axis, and both in a span with the clock) while the modes change
    between polls (axis 2 to Jog and back to Trap); ``general``: a watch hook that does
    nothing, so every cycle goes the general way.  What was read, the cycles run, and how
    often a value function was asked."""
    import cProfile

    with _auto(general) as ctl:
        assert gt.GT_AxisOn(1) == 0 and gt.GT_AxisOn(2) == 0
        trap_move(1, 40_000, 10.0)
        mode, modes, clk = c_long(), (c_long * 2)(), ctypes.c_ulong()
        seen: list = []
        pr = cProfile.Profile()
        t0 = ctl.clock.cycles
        for rnd in range(4):
            if rnd % 2:
                jog = gt.TJogPrm(acc=0.5, dec=0.5, smooth=0)
                assert gt.GT_PrfJog(2) == 0 and gt.GT_SetJogPrm(2, byref(jog)) == 0
            else:
                trap_move(2, 500 * (rnd + 1), 8.0)
            pr.enable()
            for _ in range(2000):
                assert gt.GT_GetPrfMode(2, byref(mode)) == 0
                assert gt.GT_GetPrfMode(1, modes, 2, byref(clk)) == 0
                seen.append((mode.value, *modes, clk.value))
            pr.disable()
        values = _calls(pr, ("f", "value_gt", "value_gtn"))
        return seen, ctl.clock.cycles - t0, values


def test_profile_modes_stand_across_cycles_booked_in_c() -> None:
    """A profile's mode, which no cycle changes, is not asked again after each cycle the
    entries book themselves: every poll reads what it reads with every cycle the general
    way, the modes' changes between polls included."""
    quick, cycles, asked = _mode_polls(False)
    general, _, asked_general = _mode_polls(True)
    assert quick == general
    assert len({x[:3] for x in quick}) >= 2  # (axis 2 in Trap and in Jog)
    assert asked_general > cycles  # (every cycle: both asked again)
    assert asked < cycles / 10


def _raw_polls(general: bool) -> tuple[list, int, int]:
    """Both axes moving in Trap on the auto clock, the whole raw image and one slave's
    inputs read every call (``GT_GetEcatRawData``: into a ctypes array and a bytearray);
    ``general``: a watch hook that does nothing, so every cycle goes the general way.  What
    was read, the cycles run, and how often the raw reader's value function was asked."""
    import cProfile
    import pstats

    with _auto(general) as ctl:
        assert gt.GT_AxisOn(1) == 0 and gt.GT_AxisOn(2) == 0
        whole, inputs = (ctypes.c_ubyte * 40)(), bytearray(10)
        seen: list = []
        pr = cProfile.Profile()
        t0 = ctl.clock.cycles
        for rnd in range(3):
            trap_move(1, 400 * (rnd + 1) * (-1) ** rnd, 12.0)
            trap_move(2, -300 * (rnd + 1), 9.0)
            pr.enable()
            for _ in range(2500):  # (the moves end inside a round)
                assert gt.GT_GetEcatRawData(0, 40, whole) == 0
                assert gt.GT_GetEcatRawData(22, 10, inputs) == 0
                seen.append((bytes(whole), bytes(inputs)))
            pr.disable()
        stats = pstats.Stats(pr).stats.items()  # type: ignore[attr-defined]
        asked = sum(v[1] for (file, _, _), v in stats if file.startswith("<gt raw value "))
        return seen, ctl.clock.cycles - t0, asked


def test_raw_ranges_stand_across_cycles_booked_in_c() -> None:
    """Where a raw range lies in the process image is not asked again after each cycle the
    entries book themselves (the cycle moves the image's bytes, never its buffer): every
    read copies what it copies with every cycle the general way, while the axes move."""
    quick, cycles, asked = _raw_polls(False)
    general, _, asked_general = _raw_polls(True)
    assert quick == general
    assert len(set(quick)) > cycles / 2  # (positions that move cycle by cycle)
    assert asked_general > cycles  # (every cycle: both ranges asked again)
    assert asked < cycles / 10
