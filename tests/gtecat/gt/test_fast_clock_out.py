"""A polled reader given a clock pointer (``GT_GetSts(1, sts, 12, &clock)``, the vendor's own
form for a loop that timestamps what it reads) answers as its table path: the values, the
clock, the return code and the last error; the shapes the fast path takes skip the table."""

from __future__ import annotations

import ctypes
from ctypes import byref

import numpy as np
import pytest

from gtecat import gt
from gtecat.gt.fast import READERS

from .conftest import bring_up

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
