"""A polled reader given a clock pointer (``GT_GetSts(1, sts, 12, &clock)``, the vendor's own
form for a loop that timestamps what it reads) answers as its table path: the values, the
clock, the return code and the last error; the shapes the fast path takes skip the table."""

from __future__ import annotations

import ctypes
from ctypes import byref
from itertools import pairwise

import numpy as np
import pytest

from gtecat import gt
from gtecat.gt.fast import READERS

from .conftest import bring_up, trap_move

#: pClock shapes: (what, maker); None: NULL; the table path answers the rest the same
CLOCKS = [
    ("byref c_ulong", lambda: (o := ctypes.c_ulong(), byref(o), o)),
    ("c_uint32 itself", lambda: (o := ctypes.c_uint32(), o, o)),
    ("byref c_long", lambda: (o := ctypes.c_long(), byref(o), o)),
    ("byref c_int32", lambda: (o := ctypes.c_int32(), byref(o), o)),
    ("byref c_short", lambda: (o := ctypes.c_short(), byref(o), o)),  # too narrow: 7
    ("byref c_double", lambda: (o := ctypes.c_double(), byref(o), o)),  # not an integer: 7
    ("numpy uint32", lambda: (o := np.zeros(1, np.uint32), o, o)),
    ("NULL 0", lambda: (None, 0, None)),
]


@pytest.fixture
def bus() -> None:
    bring_up("twelve_axes.eni", clock="lockstep")
    for a in range(1, 13):
        gt.GT_AxisOn(a)
    gt.GTE_Wait(1234)  # a clock that is not a round number


def _value(o):
    if o is None:
        return None
    return o.tolist() if isinstance(o, np.ndarray) else o.value


def _read(fn, ctype, count: int, clock_maker):
    arr = (ctype * count)()
    _, pclock, obj = clock_maker()
    rc = fn(1, arr, count, pclock)
    return rc, list(arr), _value(obj), gt.GTE_GetLastError() if rc else ""


@pytest.mark.parametrize("count", [1, 12])
def test_a_clock_pointer_answers_as_the_table(bus, count: int) -> None:
    seen = set()
    for name, (_, types) in READERS.items():
        fn = getattr(gt, name)
        ctype = ctypes.c_double if ctypes.c_double in types else ctypes.c_int32
        n = min(count, 8) if "Enc" in name and count > 1 else count
        for what, maker in CLOCKS:
            fast = _read(fn, ctype, n, maker)
            slow = _read(fn.slow, ctype, n, maker)
            assert fast == slow, (name, what, count)
            seen.add((what, fast[0]))
    assert ("byref c_ulong", 0) in seen and ("byref c_short", 7) in seen


def test_the_common_clock_shapes_skip_the_table(bus, monkeypatch: pytest.MonkeyPatch) -> None:
    calls = []
    slow = gt.GT_GetSts.slow
    monkeypatch.setattr(gt.GT_GetSts, "slow", lambda *a, **k: calls.append(a) or slow(*a, **k))
    sts = (ctypes.c_long * 12)()
    clk = ctypes.c_ulong()
    for count in (1, 12):
        assert gt.GT_GetSts(1, sts, count, byref(clk)) == 0
        assert gt.GT_GetSts(1, sts, count, clk) == 0
    ms = ctypes.c_ulong()
    assert gt.GT_GetClock(byref(ms)) == 0
    assert clk.value == ms.value > 1234 and not calls


#: a reader's value and clock pointers as a client passes them (pValue, count, pClock),
#: made from the value's type and two clock objects
SHAPES = {
    "byref, byref clock": lambda t, o, c, c32: (byref(o), 1, byref(c)),
    "object, clock object": lambda t, o, c, c32: (o, 1, c),
    "byref, int32 clock": lambda t, o, c, c32: (byref(o), 1, byref(c32)),
    "pointer, byref clock": lambda t, o, c, c32: (ctypes.pointer(o), 1, byref(c)),
    "array[1], byref clock": lambda t, o, c, c32: ((t * 1)(), 1, byref(c)),
    "numpy[1], byref clock": lambda t, o, c, c32: (
        np.zeros(1, np.float64 if t is ctypes.c_double else np.int32),
        1,
        byref(c),
    ),
    "span, byref clock": lambda t, o, c, c32: ((t * 2)(), 2, byref(c)),
    "&arr[1], span, clock object": lambda t, o, c, c32: (byref((t * 4)(), ctypes.sizeof(t)), 2, c),
    "span, int32 clock": lambda t, o, c, c32: ((t * 2)(), 2, c32),
}


def _written(p) -> bytes:
    if isinstance(p, np.ndarray):
        return p.tobytes()
    if type(p).__name__ == "CArgObject":
        p = p._obj
    elif isinstance(p, ctypes._Pointer):
        p = p.contents
    return bytes(p)


def _session(table: bool, clock: str) -> tuple[list, int]:
    """Both axes' Trap moves with GT_Reset now and then, each step's reads of every reader
    in every clock shape (``table``: through the table path): what was read and how many
    reads took the Python fast path's general way or the table path instead of the C
    entry."""
    import cProfile
    import pstats

    bring_up(clock=clock, cycle_ms=0.25)  # (GT_Reset between two milliseconds)
    try:
        assert gt.GT_AxisOn(1) == 0 and gt.GT_AxisOn(2) == 0
        trap_move(1, 900, 12.0)
        trap_move(2, -600, 7.5)
        ctl = gt.GTE_Controller()
        seen: list = []
        pr = cProfile.Profile()
        for step in range(48):
            if step % 11 == 5:
                assert gt.GT_Reset() == 0  # (GT_GetClock from 0 again)
            if clock == "lockstep":
                assert gt.GTE_Wait(1 + step % 3) == 0
            pr.enable()
            for name in sorted(READERS):
                fn = getattr(gt, name)
                fn = fn.slow if table else fn
                t = ctypes.c_double if ctypes.c_double in READERS[name][1] else ctypes.c_long
                for shape, make in SHAPES.items():
                    o, c, c32 = t(), ctypes.c_ulong(), ctypes.c_int32()
                    p, count, pc = make(t, o, c, c32)
                    rc = fn(1, p, count, pc)
                    seen.append(
                        (ctl.clock.cycles, name, shape, rc, _written(p), c.value, c32.value)
                    )
            pr.disable()
        stats = pstats.Stats(pr).stats.items()  # type: ignore[attr-defined]
        python = sum(
            v[1]
            for (file, _, func), v in stats
            if (func in ("call", "run") and file.endswith("_core.py"))
            or (func in ("general", "many") and file.endswith("fast.py"))
        )
        return seen, python
    finally:
        gt.GT_Close()


@pytest.mark.parametrize("clock", ["lockstep", "auto"])
def test_clock_shapes_read_the_table_values_across_reset_and_cycles(clock: str) -> None:
    """Every reader's clock shapes through the C entries (none through Python: the value and
    the clock written there) and through the table path, step by step while two axes move,
    over GT_Reset and cycles of a quarter millisecond: the values, the clocks and the codes
    agree."""
    fast, python = _session(False, clock)
    table, _ = _session(True, clock)
    assert python == 0
    assert len({c for c, *_ in fast}) > 40  # (cycles between the steps)
    clocks = [ms for *_, ms, _ in fast]
    assert any(b < a for a, b in pairwise(clocks))  # (GT_Reset seen)
    assert fast == table
