"""A polled reader given ``pointer(x)`` (a ctypes pointer object, as some wrappers pass) answers
as its table path: the value, the return code and the last error; a NULL pointer, a pointer
to another type and other objects the fast path does not take are the table path's."""

from __future__ import annotations

import ctypes

import numpy as np

from gtecat import gt
from gtecat.gt.fast import READERS

from .conftest import bring_up
from .test_fast_clock_out import _value


def _shapes(ctype: type) -> list[tuple[str, object]]:
    other = ctypes.c_short if ctype is not ctypes.c_short else ctypes.c_double
    return [
        ("pointer", lambda: (o := ctype(), ctypes.pointer(o), o)),
        ("NULL pointer", lambda: (None, ctypes.POINTER(ctype)(), None)),
        ("pointer to another type", lambda: (o := other(), ctypes.pointer(o), o)),
        ("2-D numpy array", lambda: (o := np.zeros((2, 2)), o, o)),
    ]


def _call(fn, maker) -> tuple:
    _, arg, obj = maker()
    rc = fn(1, arg)
    return rc, _value(obj), gt.GTE_GetLastError() if rc else ""


def test_a_pointer_object_answers_as_the_table() -> None:
    bring_up(clock="lockstep")
    gt.GT_AxisOn(1)
    gt.GTE_Wait(10)
    codes = set()
    for name, (_, types) in READERS.items():
        fn = getattr(gt, name)
        ctype = ctypes.c_double if ctypes.c_double in types else ctypes.c_int32
        for what, maker in _shapes(ctype):
            fast = _call(fn, maker)
            assert fast == _call(fn.slow, maker), (name, what)
            codes.add((what, fast[0]))
    assert ("pointer", 0) in codes and ("NULL pointer", 0) not in codes
