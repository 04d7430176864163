"""A walk of the fast path's functions: every way a client passes the value's pointer.

For each function with a fast path (the raw image functions have their own tests), the
pointer its value goes to is passed in each shape a client uses - ``byref`` of a reused and
of a fresh object, the ctypes object itself, a ctypes array and a numpy array (their first
element), NULL (0 or None) for the optional pointers after it - and in shapes the table path
refuses or converts (an offset, a narrower or a floating type, numpy dtypes of every width,
a two-dimensional array), and a pointer into an array (``byref(arr)``, ``byref(arr, k *
sizeof(elem))``: C's ``&arr[k]``, a span of values there for the readers of a span; past its
end, between two elements or of a narrower element the table path refuses).  Every call
answers as the table path does (code, what was written, reason); a client's shape that
reaches the table must be listed in ``fast.SLOW_SHAPES`` with its reason.
"""

from __future__ import annotations

import cProfile
import ctypes
from ctypes import byref

import numpy as np
import pytest

from gtecat import gt
from gtecat.gt import fast
from gtecat.gt.args import _scalar_types
from gtecat.gt.table import FUNCTIONS

from .conftest import bring_up
from .profiled import table_calls

#: the value a function reads first (an axis, an input or output type)
FIRST = {"GT_GetDi": 3, "GT_GetDiRaw": 0, "GT_GetDo": 10}
#: a client's shapes: each must be answered by the fast path (or listed in SLOW_SHAPES)
CLIENT = (
    "byref reused",
    "byref fresh",
    "object",
    "array[1]",
    "numpy[1]",
    "null 0",
    "null None",
    "null pointer",
    "null c_void_p",
    "byref array",
    "byref array offset",
    "keywords",
    "memoryview",
)
#: other shapes: answered as the table answers them, by whichever path (a span of the
#: readers' values into an array: the fast path's, whose steps the walk's profile counts
#: with the table's)
OTHER = (
    "byref array span",
    "byref array past",
    "byref array mid",
    "byref array narrow",
    "narrow",
    "double",
    "array[2] uint",
    "numpy int8",
    "numpy int16",
    "numpy uint16",
    "numpy uint32",
    "numpy float64",
    "numpy 2-d",
    "numpy read-only",
)
_HELD: dict[type, tuple] = {}


def _type(name: str) -> type:
    """The ctypes type a client passes for the function's value."""
    if name in fast.STRUCT_READERS:
        return fast.STRUCT_READERS[name][0]
    types = _scalar_types(_pointer(name)[1])
    for t in (ctypes.c_double, ctypes.c_long, ctypes.c_short):
        if t in types:
            return t
    raise AssertionError(f"{name}: no usual type in {types}")


def _pointer(name: str) -> tuple[int, object]:
    params = FUNCTIONS[name].params
    i = next(k for k, p in enumerate(params) if p.pointer)
    return i, params[i]


_NP = {ctypes.c_double: np.float64, ctypes.c_long: np.int64, ctypes.c_short: np.int16}


def _arg(shape: str, t: type) -> tuple[object, object, tuple]:
    """(the argument, what shows what was written, the arguments after it)."""
    if shape == "byref reused":
        if t not in _HELD:
            o = t()
            _HELD[t] = (o, byref(o))
        o, p = _HELD[t]
        return p, o, ()
    if shape.startswith("null"):  # (NULL of any pointer type is NULL)
        o = t()
        null = {
            "null 0": 0,
            "null None": None,
            "null pointer": ctypes.POINTER(ctypes.c_uint32)(),
            "null c_void_p": ctypes.c_void_p(),
        }[shape]
        return byref(o), o, (null,)
    if shape == "keywords":
        o = t()
        return byref(o), o, ()
    made = {
        "byref fresh": lambda: (o := t(), byref(o)),
        "object": lambda: (o := t(), o),
        "array[1]": lambda: (o := (t * 1)(), o),
        "numpy[1]": lambda: (o := np.zeros(1, _NP.get(t, np.int64)), o),
        "byref array": lambda: (o := (t * 2)(), byref(o)),
        "memoryview": lambda: (o := (t * 1)(), memoryview(o)),
        "byref array offset": lambda: (o := (t * 3)(), byref(o, ctypes.sizeof(t))),
        "byref array span": lambda: (o := (t * 4)(), byref(o, ctypes.sizeof(t))),
        "byref array past": lambda: (o := (t * 2)(), byref(o, 2 * ctypes.sizeof(t))),
        "byref array mid": lambda: (o := (t * 2)(), byref(o, 1)),
        "byref array narrow": lambda: (o := (ctypes.c_int8 * 8)(), byref(o, 1)),
        "narrow": lambda: (o := ctypes.c_int8(), byref(o)),
        "double": lambda: (o := ctypes.c_double(), byref(o)),
        "array[2] uint": lambda: (o := (ctypes.c_uint * 2)(), o),
        "numpy 2-d": lambda: (o := np.zeros((1, 2), np.int64), o),
        "numpy read-only": lambda: (o := np.zeros(2, np.int64), o.setflags(write=False) or o),
    }
    if shape.startswith("numpy ") and shape not in made:
        dtype = np.dtype(shape.split()[1])
        made[shape] = lambda: (o := np.zeros(2, dtype), o)
    o, p = made[shape]()
    return p, o, ()


def _written(o: object) -> object:
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, ctypes.Structure | ctypes.Array):
        return bytes(o)
    return o.value  # type: ignore[attr-defined]


def _by_name(fn, args: tuple) -> int:
    """``fn`` called with each argument named as the table names it, written out as a client
    writes it (``GT_GetSts(axis=1, pSts=p)``: a call site's names, as the compiler keeps them)."""
    names = [p.name for p in FUNCTIONS[fn.__name__].params][: len(args)]
    src = f"fn({', '.join(f'{n}=a[{k}]' for k, n in enumerate(names))})"
    return eval(compile(src, "<client>", "eval"), {"fn": fn, "a": args})


def _call(fn, args: tuple, profile: bool, named: bool = False) -> tuple[int, int]:
    pr = cProfile.Profile() if profile else None
    if pr is not None:
        pr.enable()
    rc = _by_name(fn, args) if named else fn(*args)
    if pr is None:
        return rc, 0
    pr.disable()
    table = table_calls(pr, ("general", "gtn_general"))
    return rc, table


def _has_null_after(name: str) -> bool:
    i, _ = _pointer(name)
    rest = FUNCTIONS[name].params[i + 1 :]
    return bool(rest) and rest[-1].pointer and rest[-1].default is not None


def _walk(names: list[str]) -> list[str]:
    bad = []
    for name in names:
        t = _type(name)
        i, _ = _pointer(name)
        before = (FIRST.get(name, 1),) * i
        fn = getattr(gt, name)
        for shape in CLIENT + OTHER:
            if shape.startswith("null") and not _has_null_after(name):
                continue
            if shape == "byref array span" and name not in fast.READERS:
                continue
            if shape.startswith("null") and name in fast.READERS:
                shape_args = (1,)  # (count 1, then pClock NULL)
            elif shape == "byref array span":
                shape_args = (2, None)  # (two axes' values from the array's second element)
            else:
                shape_args = ()
            got = []
            for which in (fn, fn.slow):
                p, o, after = _arg(shape, t)
                rc, table = _call(
                    which, (*before, p, *shape_args, *after), which is fn, shape == "keywords"
                )
                got.append((rc, _written(o), gt.GTE_GetLastError() if rc else "", table))
            if got[0][:3] != got[1][:3]:
                bad.append(f"{name} {shape}: {got[0][:3]} != {got[1][:3]}")
            elif (
                shape in CLIENT
                and got[0][0] == 0
                and got[0][3]
                and shape not in fast.SLOW_SHAPES.get(name, {})
            ):
                bad.append(f"{name} {shape}: on the table path without a reason")
    return bad


# (the table path's numpy reads a ctypes array's view of c_long, whose format says 4 bytes
# and whose items are 8, with a warning: its guess is the array's own type)
@pytest.mark.filterwarnings("ignore:A builtin ctypes object gave a PEP3118:RuntimeWarning")
def test_every_client_shape_of_every_fast_function() -> None:
    bring_up(clock="lockstep")
    assert gt.GT_AxisOn(1) == 0 and gt.GT_PrfTrap(1) == 0
    prm = gt.TTrapPrm(acc=0.5, dec=0.5, velStart=0, smoothTime=0)
    assert gt.GT_SetTrapPrm(1, byref(prm)) == 0
    assert gt.GT_SetPos(1, 40_000) == 0 and gt.GT_SetVel(1, 20) == 0 and gt.GT_Update(1) == 0
    assert gt.GT_SetDo(gt.MC_GPO, 0x0102) == 0
    gt.GTE_Wait(30)  # (moving: positions, speeds and the clock are not 0)
    names = sorted(fast.fast_functions() - fast.RAW)
    bad = _walk(names)
    assert not bad, "\n".join(bad[:30])
    for name, shapes in fast.SLOW_SHAPES.items():
        assert name in fast.fast_functions(), name
        for shape, reason in shapes.items():
            assert shape in CLIENT and reason.strip(), (name, shape)


def test_the_derived_readers_read_their_properties_inline() -> None:
    """The readers fast.DERIVED and fast.UNBANKED read inline give their getter's value, on
    an axis the bank runs and on one it does not, with a profile and an encoder scale (a
    ratio other than 1 and an offset)."""
    from gtecat.gt.fast import DERIVED, READERS, UNBANKED

    for bank in ("on", "off"):
        gt.GT_Close()
        bring_up(clock="lockstep", bank=bank)
        ctl = gt.GTE_Controller()
        assert gt.GT_AxisOn(1) == 0 and gt.GT_AxisOn(2) == 0
        assert gt.GT_ProfileScale(1, 4, 3) == 0 and gt.GT_EncScale(1, 8, 5) == 0
        for axis in (1, 2):
            assert gt.GT_PrfTrap(axis) == 0
            prm = gt.TTrapPrm(acc=0.25, dec=0.25, velStart=0, smoothTime=0)
            assert gt.GT_SetTrapPrm(axis, byref(prm)) == 0
            assert gt.GT_SetPos(axis, 30_000) == 0 and gt.GT_SetVel(axis, 7) == 0
        assert gt.GT_Update(0b11) == 0
        for _ in range(3):
            gt.GTE_Wait(17)
            for name in [*DERIVED, *UNBANKED]:
                get, types = READERS[name]
                for axis in (1, 2):
                    v = ctypes.c_double() if ctypes.c_double in types else ctypes.c_long()
                    assert getattr(gt, name)(axis, byref(v)) == 0
                    assert v.value == get(ctl.resources[axis]), (name, axis)
        if bank == "on":
            assert any(ctl.resources[a].bank is not None for a in (1, 2)), "none in the bank"


def test_the_clock_reads_the_controller_clock_after_a_reset() -> None:
    """GT_GetClock's fast path reads the controller's milliseconds as ``clock_ms`` does,
    counted from the last GT_Reset."""
    bring_up(clock="lockstep")
    ctl = gt.GTE_Controller()
    for wait in (7, 0, 13):
        gt.GTE_Wait(wait)
        if wait == 0:
            assert gt.GT_Reset() == 0
            gt.GTE_Wait(3)
        got, want = ctypes.c_long(), ctypes.c_long()
        assert gt.GT_GetClock(byref(got)) == 0 and gt.GT_GetClock.slow(byref(want)) == 0
        assert got.value == want.value == ctl.clock_ms() & 0xFFFFFFFF
