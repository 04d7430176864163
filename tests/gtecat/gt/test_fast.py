"""The GT fast path (gtecat.gt.fast) answers exactly as the table path does (issue 17 item 3).

Every reader is called with generated argument shapes - byref of each integer/double type,
byref with an offset, arrays, pointers, wrong types, out-of-range axes, count and pClock
given or not, keywords - once through the public function (fast path in front) and once
through its table path (``.slow``); return code, written value and GTE_GetLastError agree.
"""

from __future__ import annotations

import ctypes
from ctypes import byref
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gtecat import gt
from gtecat.gt.fast import READERS
from tests.conftest import examples

ENI = Path(__file__).resolve().parents[3] / "examples" / "twelve_axes.eni"


@pytest.fixture
def moving_bus():
    """After the directory's autouse fixture closed any controller: a bus with 3 axes moving."""
    gt.GT_Close()
    assert gt.GT_Open(eni=str(ENI), clock="lockstep", log="") == 0
    assert gt.GT_InitEcatComm() == 0
    gt.GTE_Wait(60)
    assert gt.GT_StartEcatComm() == 0
    for a in (1, 2, 5):
        assert gt.GT_AxisOn(a) == 0
        prm = gt.TTrapPrm()
        prm.acc, prm.dec, prm.smoothTime = 0.5, 0.5, 10
        gt.GT_PrfTrap(a)
        gt.GT_SetTrapPrm(a, byref(prm))
        gt.GT_SetPos(a, 90_000 * a)
        gt.GT_SetVel(a, 10)
    gt.GT_Update(0b10011)
    gt.GTE_Wait(300)
    yield
    gt.GT_Close()


TYPES = [ctypes.c_int32, ctypes.c_long, ctypes.c_int16, ctypes.c_double, ctypes.c_float]
shape = st.sampled_from(
    [
        "byref",
        "byref_offset",
        "scalar_offset",
        "same_byref",
        "array",
        "array1",
        "pointer",
        "obj",
        "int",
        "struct_field",  # byref(s, S.field.offset): C's &s.field
        "numpy",  # a numpy array of t's element type
        "numpy_u8",  # a one-byte numpy array (narrower than any reader's type)
        "memoryview_u8",
        "released_memoryview",
    ]
)
_SAME: dict[type, tuple] = {}


def _arg(kind: str, t: type):
    if kind == "byref":
        o = t()
        return o, byref(o)
    if kind == "byref_offset":
        o = (t * 3)()
        return o, byref(o, ctypes.sizeof(t))
    if kind == "scalar_offset":  # past the end of a scalar: the table refuses it (7)
        o = t()
        return o, byref(o, 4)
    if kind == "same_byref":  # one pointer object used again and again (a C-style loop)
        if t not in _SAME:
            o = t()
            _SAME[t] = (o, byref(o))
        return _SAME[t]
    if kind == "array":
        o = (t * 4)()
        return o, o
    if kind == "array1":
        o = (t * 1)()
        return o, o
    if kind == "pointer":
        o = t()
        return o, ctypes.pointer(o)
    if kind == "obj":
        o = t()
        return o, o
    if kind == "struct_field":

        class S(ctypes.Structure):
            _fields_ = [("tag", ctypes.c_short), ("x", t), ("after", ctypes.c_short)]

        o = S(tag=-3, after=-4)
        return o, byref(o, S.x.offset)
    if kind == "numpy":
        o = np.zeros(2, np.dtype(t._type_))
        return o, o
    if kind == "numpy_u8":
        o = np.zeros(8, np.uint8)
        return o, o
    if kind == "memoryview_u8":
        o = bytearray(8)
        return o, memoryview(o)
    if kind == "released_memoryview":
        m = memoryview(bytearray(8))
        m.release()
        return None, m
    return None, 12345


def _value(o):
    if o is None:
        return None
    if isinstance(o, ctypes.Structure):
        return [getattr(o, f[0]) for f in o._fields_]
    if isinstance(o, np.ndarray | bytearray):
        return list(o)
    if isinstance(o, ctypes.Array):
        return [o[i] for i in range(len(o))]
    return o.value


@settings(
    max_examples=examples(150, 19),
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(
    name=st.sampled_from(sorted(READERS)),
    axis=st.one_of(st.integers(-2, 14), st.just(1.0), st.just("1"), st.just(True)),
    kind=shape,
    t=st.sampled_from(TYPES),
    count=st.sampled_from([None, 1, 2, 0]),
    clock=st.booleans(),
)
def test_fast_path_answers_as_the_table(moving_bus, name, axis, kind, t, count, clock) -> None:
    fast = getattr(gt, name)
    results = []
    for fn in (fast, fast.slow):
        o, p = _arg(kind, t)
        args = [axis, p]
        if count is not None or clock:
            args.append(1 if count is None else count)
        clk = ctypes.c_uint32()
        if clock:
            args.append(byref(clk))
        rc = fn(*args)
        results.append((rc, _value(o), gt.GTE_GetLastError() if rc else "", clk.value))
    assert results[0] == results[1]
    assert results[0][0] != -1, "the controller must be open"


def test_fast_path_is_taken_for_the_common_shape(moving_bus) -> None:
    """The common shape costs a handful of calls (counted with a profiler, not timed)."""
    import cProfile
    import pstats

    s = ctypes.c_long()
    pr = cProfile.Profile()
    pr.enable()
    for _ in range(100):
        gt.GT_GetSts(1, byref(s))
    pr.disable()
    calls = pstats.Stats(pr).total_calls
    assert calls / 100 <= 11, calls / 100  # byref, the wrapper and its checks, status, bank row
    assert s.value & 0x600 == 0x600  # servo on, moving


def test_keywords_and_gtn_take_the_table_path(moving_bus) -> None:
    a, b = ctypes.c_double(), ctypes.c_double()
    assert gt.GT_GetPrfPos(profile=2, pValue=byref(a)) == 0
    assert gt.GTN_GetPrfPos(1, 2, byref(b)) == 0
    assert a.value == b.value != 0.0


def test_the_clock_reader_answers_as_the_table(moving_bus) -> None:
    """GT_GetClock's fast path (pClock of an integer type, pLoop NULL) against its table path,
    a clock past what a 32-bit signed pClock holds included."""
    ctl = gt.GTE_Controller()
    bad = []
    for reset_ns in (ctl.reset_ns, ctl.clock.now_ns - (1 << 31) * 1_000_000):
        ctl.reset_ns = reset_ns
        for kind in ("byref", "byref_offset", "same_byref", "array", "obj", "int"):
            for t in (
                ctypes.c_long,
                ctypes.c_int32,
                ctypes.c_int16,
                ctypes.c_double,
                ctypes.c_ulong,  # the vendor's unsigned long *pClock
                ctypes.c_uint32,
            ):
                for loop in ("omitted", "none", "zero", "byref"):
                    results = []
                    for fn in (gt.GT_GetClock, gt.GT_GetClock.slow):
                        o, p = _arg(kind, t)
                        loops = ctypes.c_uint32()
                        extra = {"omitted": (), "none": (None,), "zero": (0,)}
                        rc = fn(p, *extra.get(loop, (byref(loops),)))
                        err = gt.GTE_GetLastError() if rc else ""
                        results.append((rc, _value(o), err, loops.value))
                    if results[0] != results[1]:
                        bad.append(f"{kind} {t.__name__} {loop}: {results}")
    assert not bad, "\n".join(bad)


def test_every_axis_in_one_call_answers_as_the_table(moving_bus) -> None:
    """count > 1 into a ctypes array (``GT_GetSts(1, sts, 12, NULL)``, a poll of every axis):
    the fast answer is the table's, spans past the axes, the encoders' limit of 8, arrays
    too short, other types, a clock pointer and numpy arrays included."""
    import numpy as np

    bad = []
    for name in sorted(READERS):
        for first, count in (
            (1, 12),
            (1, 2),
            (5, 8),
            (9, 4),
            (1, 8),
            (1, 9),
            (6, 8),
            (0, 3),
            (12, 2),
        ):
            for kind in ("c_long", "c_int32", "c_double", "c_float", "short", "numpy", "clock"):
                results = []
                for fn in (getattr(gt, name), getattr(gt, name).slow):
                    n = count - 1 if kind == "short" else 12
                    t = {"c_int32": ctypes.c_int32, "c_double": ctypes.c_double}.get(kind)
                    if kind == "c_float":
                        t = ctypes.c_float
                    if t is None:
                        t = (
                            ctypes.c_double
                            if READERS[name][1] is READERS["GT_GetPrfPos"][1]
                            else ctypes.c_long
                        )
                    o = np.zeros(12) if kind == "numpy" else (t * max(n, 1))()
                    clk = ctypes.c_uint32()
                    rc = fn(first, o, count, byref(clk) if kind == "clock" else None)
                    err = gt.GTE_GetLastError() if rc else ""
                    results.append((rc, list(o), err, clk.value))
                if results[0] != results[1]:
                    bad.append(f"{name}({first}, {kind}, {count}): {results}")
    assert not bad, "\n".join(bad[:5])
    sts = (ctypes.c_long * 12)()
    assert gt.GT_GetSts(1, sts, 12, None) == 0
    assert [sts[a - 1] & 0x600 for a in (1, 2, 5)] == [0x600] * 3  # servo on, moving


def test_many_axes_follow_the_bank_as_axes_leave_and_come_back(moving_bus) -> None:
    """A read of many axes at once keeps the bank's rows of its span between calls: an axis
    given back (switched off: it stays out while its status changes), switched on and
    claimed again, and the cycles between all read as the table path reads them."""
    ctl = gt.GTE_Controller()
    assert ctl.bank is not None
    for a in range(1, 13):
        gt.GT_AxisOn(a)
    gt.GTE_Wait(20)
    assert ctl.bank.n_alive == 12
    sts, prf = (ctypes.c_long * 12)(), (ctypes.c_double * 12)()
    sts2, prf2 = (ctypes.c_long * 12)(), (ctypes.c_double * 12)()
    seen = []
    for step, act in enumerate(
        [None, ("off", 7), ("wait", 5), ("on", 7), ("wait", 40), ("off", 1), ("wait", 3)]
    ):
        if act is not None and act[0] == "off":
            assert gt.GT_AxisOff(act[1]) == 0  # gives the axis back; it stays out
        elif act is not None and act[0] == "on":
            assert gt.GT_AxisOn(act[1]) == 0
        elif act is not None:
            gt.GTE_Wait(act[1])  # cycles: new values, the axis claimed again once on
        seen.append(ctl.bank.n_alive)
        for fn, a, b in ((gt.GT_GetSts, sts, sts2), (gt.GT_GetPrfPos, prf, prf2)):
            assert fn(1, a, 12, None) == 0
            assert fn.slow(1, b, 12, None) == 0
            assert list(a) == list(b), (step, fn.__name__)
            assert fn(3, a, 8, None) == 0  # another span of the same bank
            assert fn.slow(3, b, 8, None) == 0
            assert list(a)[:8] == list(b)[:8], (step, fn.__name__)
    assert seen[0] == 12 and min(seen) < 12 and 12 in seen[3:]  # out and back while read
