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
from .profiled import table_calls

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
    # the clock as pointer(x) (the value's too), and numpy arrays of several values
    "byref, pointer clock": lambda t, o, c, c32: (byref(o), 1, ctypes.pointer(c)),
    "pointer, pointer int32 clock": lambda t, o, c, c32: (
        ctypes.pointer(o),
        1,
        ctypes.pointer(c32),
    ),
    "span, pointer clock": lambda t, o, c, c32: ((t * 2)(), 2, ctypes.pointer(c)),
    "numpy span, byref clock": lambda t, o, c, c32: (np.zeros(3, _np(t)), 2, byref(c)),
    "numpy span, int32 clock": lambda t, o, c, c32: (np.zeros(2, _np(t)), 2, c32),
    "numpy span, NULL": lambda t, o, c, c32: (np.zeros(4, _np(t)), 4, None),
}

#: shapes the fast path refuses (the table path answers them: a code 7 and its reason, or
#: its own values): a numpy array of another dtype, strided, read-only, too short or of two
#: dimensions; a NULL pointer or one to another type as the clock
REFUSED = {
    "numpy span, other dtype": lambda t, o, c, c32: (np.zeros(2, np.float32), 2, byref(c)),
    "numpy span, int16": lambda t, o, c, c32: (np.zeros(2, np.int16), 2, None),
    "numpy span, strided": lambda t, o, c, c32: (np.zeros(4, _np(t))[::2], 2, byref(c)),
    "numpy span, read-only": lambda t, o, c, c32: (_read_only(np.zeros(2, _np(t))), 2, c),
    "numpy span, too short": lambda t, o, c, c32: (np.zeros(2, _np(t)), 3, byref(c)),
    "numpy span, 2-D": lambda t, o, c, c32: (np.zeros((2, 2), _np(t)), 2, byref(c)),
    "span, NULL pointer clock": lambda t, o, c, c32: (
        (t * 2)(),
        2,
        ctypes.POINTER(ctypes.c_ulong)(),
    ),
    "byref, NULL pointer clock": lambda t, o, c, c32: (
        byref(o),
        1,
        ctypes.POINTER(ctypes.c_ulong)(),
    ),
    "byref, pointer short clock": lambda t, o, c, c32: (
        byref(o),
        1,
        ctypes.pointer(ctypes.c_short()),
    ),
    "NULL pointer value": lambda t, o, c, c32: (ctypes.POINTER(t)(), 1, byref(c)),
}


def _np(t: type) -> type:
    return np.float64 if t is ctypes.c_double else np.int32


def _read_only(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


def _written(p) -> bytes:
    if isinstance(p, np.ndarray):
        return p.tobytes()
    if type(p).__name__ == "CArgObject":
        p = p._obj
    elif isinstance(p, ctypes._Pointer):
        if not p:
            return b"NULL"
        p = p.contents
    return bytes(p)


def _way(fn, way: str):
    """``fn`` itself (``c``: its C entry where there is one), its Python fast function
    (``python``) or its table path (``table``)."""
    return fn.slow if way == "table" else getattr(fn, "python", fn) if way == "python" else fn


def _session(
    way: str, clock: str, shapes: dict = SHAPES, steps: int = 48, counted: bool = True
) -> tuple[list, int]:
    """Both axes' Trap moves with GT_Reset now and then, each step's reads of every reader
    in every clock shape (``table``: through the table path): what was read and how many
    reads took the Python fast path's general way or the table path instead of the C
    entry (``counted``: else 0 - the count profiles every read, which triples the cost of
    shapes the table path answers)."""
    import cProfile

    bring_up(clock=clock, cycle_ms=0.25)  # (GT_Reset between two milliseconds)
    try:
        assert gt.GT_AxisOn(1) == 0 and gt.GT_AxisOn(2) == 0
        trap_move(1, 900, 12.0)
        trap_move(2, -600, 7.5)
        ctl = gt.GTE_Controller()
        seen: list = []
        # (only the C entries' run counts)
        pr = cProfile.Profile() if way == "c" and counted else None
        for step in range(steps):
            if step % 11 == 5:
                assert gt.GT_Reset() == 0  # (GT_GetClock from 0 again)
            if clock == "lockstep":
                assert gt.GTE_Wait(1 + step % 3) == 0
            if pr:
                pr.enable()
            for name in sorted(READERS):
                fn = _way(getattr(gt, name), way)
                t = ctypes.c_double if ctypes.c_double in READERS[name][1] else ctypes.c_long
                for shape, make in shapes.items():
                    o, c, c32 = t(), ctypes.c_ulong(), ctypes.c_int32()
                    p, count, pc = make(t, o, c, c32)
                    rc = fn(1, p, count, pc)
                    why = gt.GTE_GetLastError() if rc else ""
                    seen.append(
                        (ctl.clock.cycles, name, shape, rc, _written(p), c.value, c32.value, why)
                    )
            if pr:
                pr.disable()
        if pr is None:
            return seen, 0
        python = table_calls(pr, ("general", "many"))
        return seen, python
    finally:
        gt.GT_Close()


@pytest.mark.parametrize(
    "clock",
    [
        "lockstep",
        # (the default run: the lockstep clock's; the auto clock's clock shapes in
        # test_refused_shapes_answer_as_the_table and the clock-and-loop pointers below)
        pytest.param("auto", marks=pytest.mark.long("the same session on the auto clock")),
    ],
)
def test_clock_shapes_read_the_table_values_across_reset_and_cycles(clock: str) -> None:
    """Every reader's clock shapes through the C entries (none through Python: the value and
    the clock written there) and through the table path, step by step while two axes move,
    over GT_Reset and cycles of a quarter millisecond: the values, the clocks and the codes
    agree."""
    fast, python = _session("c", clock)
    table, _ = _session("table", clock)
    assert python == 0
    assert len({c for c, *_ in fast}) > 40  # (cycles between the steps)
    clocks = [ms for *_, ms, _, _ in fast]
    assert any(b < a for a, b in pairwise(clocks))  # (GT_Reset seen)
    assert fast == table
    assert {rc for _, _, _, rc, *_ in fast} == {0}
    assert _session("python", clock)[0] == table  # (the Python fast functions: the same)


@pytest.mark.parametrize(
    "clock",
    [
        # (the default run: the auto clock's; the lockstep clock's across GT_Reset above)
        pytest.param("lockstep", marks=pytest.mark.long("the same session on the lockstep clock")),
        "auto",
    ],
)
def test_refused_shapes_answer_as_the_table(clock: str) -> None:
    """The shapes the fast path does not take (a numpy array it cannot write whole, a NULL
    pointer, a clock pointer of another type) answer as the table path does, step by step:
    the same codes, reasons and values."""
    fast, _ = _session("c", clock, REFUSED, 16, counted=False)  # (the table answers them)
    table, _ = _session("table", clock, REFUSED, 16)
    assert fast == table
    assert _session("python", clock, REFUSED, 16)[0] == table
    codes = {(shape, rc) for _, _, shape, rc, *_ in fast}
    # (a NULL pointer clock is C's NULL: no clock; a numpy array of two dimensions the table
    # path writes flat)
    assert ("numpy span, int16", 7) in codes and ("byref, NULL pointer clock", 0) in codes


#: GT_GetClock's two pointers as clients pass them (the vendor's ``GT_GetClock(&clk, &loop)``):
#: (pClock, pLoop) made from a clock and a loop object of the types given
LOOPS = {
    "byref, byref": lambda c, lp: (byref(c), byref(lp)),
    "objects": lambda c, lp: (c, lp),
    "pointers": lambda c, lp: (ctypes.pointer(c), ctypes.pointer(lp)),
    "byref, pointer": lambda c, lp: (byref(c), ctypes.pointer(lp)),
    "byref, NULL": lambda c, lp: (byref(c), None),
    "byref, 0": lambda c, lp: (byref(c), 0),
    "array, byref": lambda c, lp: ((ctypes.c_ulong * 2)(), byref(lp)),
    "byref, NULL pointer": lambda c, lp: (byref(c), ctypes.POINTER(type(lp))()),
    "byref, numpy": lambda c, lp: (byref(c), np.zeros(1, np.uint32)),
    "byref, 5": lambda c, lp: (byref(c), 5),
}
#: the loop object's types: the vendor's, a wider and a signed one, too narrow, not an integer
LOOP_TYPES = [ctypes.c_ulong, ctypes.c_uint32, ctypes.c_int32, ctypes.c_short, ctypes.c_double]


def _clock_session(way: str, clock: str) -> tuple[list, int]:
    """GT_GetClock in every two-pointer shape, step by step over cycles and GT_Reset (through
    the table path where ``table``): what each wrote and returned, and how many calls took
    the Python fast function or the table path instead of the C entry (``way``: _way's)."""
    import cProfile

    bring_up(clock=clock, cycle_ms=0.25)
    try:
        seen: list = []
        fast_forms = ("byref, byref", "objects", "pointers", "byref, pointer")
        python = 0
        for step in range(24):
            if step % 9 == 4:
                assert gt.GT_Reset() == 0
            if clock == "lockstep":
                assert gt.GTE_Wait(1 + step % 3) == 0
            for lt in LOOP_TYPES:
                for shape, make in LOOPS.items():
                    c, lp = ctypes.c_ulong(), lt()
                    a, b = make(c, lp)
                    fn = _way(gt.GT_GetClock, way)
                    counted = (  # (only the C entries' run counts)
                        way == "c"
                        and shape in fast_forms
                        and lt is not ctypes.c_short
                        and lt is not ctypes.c_double
                    )
                    pr = cProfile.Profile() if counted else None
                    if pr:
                        pr.enable()
                    rc = fn(a, b)
                    if pr:
                        pr.disable()
                        python += table_calls(pr, ("gt",))
                    why = gt.GTE_GetLastError() if rc else ""
                    seen.append((step, lt.__name__, shape, rc, c.value, _written(a), lp.value, why))
        return seen, python
    finally:
        gt.GT_Close()


@pytest.mark.parametrize("clock", ["lockstep", "auto"])
def test_the_clock_and_loop_pointers_answer_as_the_table(clock: str) -> None:
    """``GT_GetClock(pClock, pLoop)`` in every shape writes what its table path writes (the
    milliseconds since GT_Reset, the cycles run) and refuses what it refuses, across cycles
    and GT_Reset; the vendor's two-pointer forms of an integer type that holds the values
    never reach Python's fast function nor the table."""
    fast, python = _clock_session("c", clock)
    table, _ = _clock_session("table", clock)
    assert fast == table
    assert _clock_session("python", clock)[0] == table
    assert python == 0
    ok = {(t, shape) for _, t, shape, rc, *_ in fast if rc == 0}
    assert ("c_ulong", "pointers") in ok and ("c_ulong", "byref, 5") not in ok
    assert len({loop for _, t, shape, rc, _, _, loop, _ in fast if shape == "pointers"}) > 10


@pytest.mark.parametrize("clock", ["lockstep", "auto"])
def test_the_clock_after_every_cycle_is_made_in_c_and_clears_the_last_error(clock: str) -> None:
    """``GT_GetClock`` polled after each ``GTE_Wait(1)`` (every cycle makes a kept value
    stale) answers from the clock in C, as its table path does, and after a failed call it
    still clears ``GTE_GetLastError`` (the Python fast function answers then)."""
    import cProfile

    bring_up("twelve_axes.eni", clock=clock)
    try:
        got, want = ctypes.c_uint32(), ctypes.c_uint32()
        loop, want_loop = ctypes.c_uint32(), ctypes.c_uint32()
        pr = cProfile.Profile()
        for k in range(40):
            gt.GTE_Wait(1)
            if k == 20:
                gt.GT_Reset()
            pr.enable()
            rc = gt.GT_GetClock(byref(got), byref(loop) if k % 2 else None)
            pr.disable()
            assert rc == 0
            assert gt.GT_GetClock.slow(byref(want), byref(want_loop)) == 0
            if clock == "lockstep":  # (on the auto clock each call's host latency moves it)
                assert got.value == want.value
                if k % 2:
                    assert loop.value == want_loop.value
            else:
                assert 0 <= want.value - got.value <= 1
        # (no Python of the entry's: neither its value function nor the fast function; on
        # the auto clock its host latency's after() runs, as every call's)
        ran = {getattr(f.code, "co_name", "") for f in pr.getstats()}
        assert not ran & {"value", "gt"}
        assert gt.GT_AxisOn(99) != 0 and gt.GTE_GetLastError()
        assert gt.GT_GetClock(byref(got), None) == 0
        assert gt.GTE_GetLastError() == ""
    finally:
        gt.GT_Close()
