"""The fast paths' C entries (gtecat/gt/centry.py) answer as the Python fast functions and
the table path do, and keep reference counts.

Each family is built twice around its table path - with its C entry and without it (the
Python fast function alone, as where no compiler is found) - and called in generated
shapes; return code, what was written (the image too, for the raw functions) and the last
error agree among the three.  The readers (on a bus whose axes the bank runs and on one
where it does not): byref of each integer and floating type (fresh, reused, with an offset,
into a structure's field), the object itself, arrays, pointers, numpy arrays and
memoryviews, wrong types, axes out of range or of another type, count and pClock in each
form (spans of axes with a clock included), keywords, the GTN_ twin with core 1, 2 and a
wrong core.  The two-argument readers (the IO readers, the PDO readers, the homing status,
the Trap parameters), GT_GetClock, and the raw image functions over every range of figure
5-2's image with each kind of buffer.  The default run samples the shapes; GTECAT_LONG=1
runs them all (a broad sample of the readers').
"""

from __future__ import annotations

import ctypes
import os
import random
import shutil
import subprocess
import sys
import types
from collections.abc import Sequence
from ctypes import byref
from math import prod
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from gtecat import gt
from gtecat.gt import _core, centry, fast
from tests.conftest import LONG

ENI = Path(__file__).resolve().parents[3] / "examples" / "manual_fig5_2.eni"
HAS_CC = any(shutil.which(c) for c in ("cc", "gcc", "clang"))
needs_cc = pytest.mark.skipif(not HAS_CC, reason="no C compiler (cc, gcc or clang) on PATH")


def _open(**options: str) -> Any:
    assert gt.GT_Open(eni=str(ENI), clock="lockstep", log="", **options) == 0
    assert gt.GT_InitEcatComm() == 0
    gt.GTE_Wait(60)
    assert gt.GT_StartEcatComm() == 0
    assert gt.GT_AxisOn(1) == 0
    prm = gt.TTrapPrm()
    prm.acc, prm.dec = 0.5, 0.5
    gt.GT_PrfTrap(1)
    gt.GT_SetTrapPrm(1, byref(prm))
    gt.GT_SetPos(1, 50_000)
    gt.GT_SetVel(1, 10)
    gt.GT_Update(1)
    gt.GTE_Wait(30)  # (moving: every reader's value non-zero)
    return gt.GTE_Controller()


def _built(name: str, in_c: bool, monkeypatch: pytest.MonkeyPatch) -> Any:
    """``name``'s public function built again around its table path, with its C entry or
    without it (its GTN_ twin's other shapes: the table's)."""
    monkeypatch.setattr(fast, "CENTRY", in_c)
    slow = getattr(gt, name).slow
    fn = fast.fast_reader(name, slow, _core.SESSION, _core.advance)
    fn.gtn_slow = getattr(gt, "GTN_" + name[3:]).__wrapped__
    return fn


class _S(ctypes.Structure):
    _fields_ = [("tag", ctypes.c_short), ("x", ctypes.c_long), ("after", ctypes.c_short)]


_HELD: dict[type, tuple] = {}
TYPES = [ctypes.c_int32, ctypes.c_long, ctypes.c_int16, ctypes.c_double, ctypes.c_float]
KINDS = [
    "byref",
    "reused",
    "offset",
    "field",
    "obj",
    "array",
    "pointer",
    "cast",
    "address",
    "numpy",
    "memoryview",
    "int",
    "none",
]


def _arg(kind: str, t: type) -> tuple[Any, Any]:
    """(what shows what was written, the argument)."""
    if kind == "byref":
        o = t()
        return o, byref(o)
    if kind == "reused":
        if t not in _HELD:
            o = t()
            _HELD[t] = (o, byref(o))
        o, p = _HELD[t]
        ctypes.memset(ctypes.addressof(o), 0, ctypes.sizeof(o))
        return o, p
    if kind == "offset":
        o = (t * 3)()
        return o, byref(o, ctypes.sizeof(t))
    if kind == "field":
        o = _S(tag=-3, after=-4)
        return o, byref(o, _S.x.offset)
    if kind == "obj":
        o = t()
        return o, o
    if kind == "array":
        o = (t * 12)()
        return o, o
    if kind == "pointer":
        o = t()
        return o, ctypes.pointer(o)
    if kind == "cast":  # a pointer cast from a smaller object: no size behind it is proved
        big = (ctypes.c_ubyte * 16)()
        return big, ctypes.cast((ctypes.c_ubyte * 2).from_buffer(big), ctypes.POINTER(t))
    if kind == "address":  # a pointer cast from an address (numpy's data_as is one)
        o = t()
        return o, ctypes.cast(ctypes.addressof(o), ctypes.POINTER(t))
    if kind == "numpy":
        o = np.zeros(2, np.dtype(t._type_))
        return o, o
    if kind == "memoryview":
        o = bytearray(8)
        return o, memoryview(o)
    return None, 5 if kind == "int" else None


def _shown(o: Any) -> Any:
    if o is None:
        return None
    if isinstance(o, ctypes.Structure | ctypes.Array):
        return bytes(o)
    if isinstance(o, np.ndarray | bytearray):
        return bytes(o)
    return o.value


AXES = [1, 2, 0, 3, 13, -1, 1 << 40, True, 1.0, "1"]
_CLK = ctypes.c_uint32()
TAILS: list[tuple] = [
    (),
    (1,),
    (1, 0),
    (1, None),
    (2,),
    (0,),
    (1, 5),
    (1, 0, 0),
    (True,),
    (2, byref(_CLK)),
    (12, None),
    (9,),
]
GTN_CORES = [None, 1, 2, True, 0]


class _Product(Sequence):
    """``itertools.product(*dims)`` as a sequence that makes only the items asked for:
    ``random.sample`` draws the same items from it as from the list, without building the
    ~600,000 tuples (half a second of every run)."""

    def __init__(self, *dims: list) -> None:
        self.dims = dims
        self.size = prod(len(d) for d in dims)

    def __len__(self) -> int:
        return self.size

    def __getitem__(self, i: int) -> tuple:  # type: ignore[override]
        if not 0 <= i < self.size:
            raise IndexError(i)
        out = []
        for d in reversed(self.dims):
            i, j = divmod(i, len(d))
            out.append(d[j])
        return tuple(reversed(out))


def _cases() -> list[tuple]:
    names = sorted(fast.READERS)
    out = _Product(names, KINDS, TYPES, AXES, TAILS, GTN_CORES)
    rnd = random.Random(30)
    if LONG:  # (all of them would take an hour: a broad sample)
        return rnd.sample(out, 30_000)
    # (the cases of those kinds and axes, in the same order: filtering a product's
    # dimensions filters its list)
    kinds = [k for k in KINDS if k in ("byref", "reused", "obj")]
    common = _Product(names, kinds, TYPES, [a for a in AXES if a in (1, 2)], TAILS, GTN_CORES)
    return rnd.sample(common, 250) + rnd.sample(out, 350)


def _call(fn: Any, gtn: bool, case: tuple, kw: bool) -> tuple:
    _, kind, t, axis, tail, core = case
    o, p = _arg(kind, t)
    args = (axis, p, *tail)
    if gtn:
        call = fn.gtn
        args = (core, *args)
    else:
        call = fn
    rc = call(*args[:-1], pClock=args[-1]) if kw and len(args) > 3 else call(*args)
    return rc, _shown(o), gt.GTE_GetLastError() if rc else ""


@needs_cc
def test_the_c_entry_is_built_and_is_the_public_reader() -> None:
    assert centry.REASON == "", centry.REASON
    for name in [
        *fast.READERS,
        *fast.RAW,
        fast.CLOCK,
        fast.HOMING,
        fast.HOME_STATUS,
        *fast.IO_READERS,
    ]:
        fn = getattr(gt, name)
        assert hasattr(fn, "python"), name  # (the C entry in front)
        assert not centry.PARTIALS, centry.PARTIALS
        assert fn.__name__ == name and "(C entry)" in repr(fn) and fn.__doc__ == fn.slow.__doc__
    import inspect

    assert str(inspect.signature(gt.GT_GetSts)) == "(axis, pSts, count=1, pClock=None)"
    made = type(gt.GT_GetSts)()  # (an object of the entry type without its C function)
    with pytest.raises(TypeError):
        made(1, ctypes.c_long())


@needs_cc
def test_an_entry_is_used_as_a_function_is() -> None:
    """Pickled, copied, weakly referenced, a routine to inspect and pydoc (its signature
    shown), bound as a method where a class holds it, as the Python function it stands for;
    and the pointer types its probes made first are ctypes' (their repr)."""
    import copy
    import inspect
    import pickle
    import pydoc
    import weakref

    for fn in (gt.GT_GetSts, gt.GTN_GetPrfPos, gt.GT_GetEcatRawData):
        assert type(fn) is not types.FunctionType, "the C entry is not in front"
        assert pickle.loads(pickle.dumps(fn)) is fn
        assert copy.copy(fn) is fn and copy.deepcopy(fn) is fn
        assert weakref.ref(fn)() is fn
        assert inspect.isroutine(fn)
    assert ("GT_GetSts", gt.GT_GetSts) in inspect.getmembers(gt, inspect.isroutine)
    assert "GT_GetSts(axis, pSts, count=1, pClock=None)" in pydoc.render_doc(
        gt.GT_GetSts, renderer=pydoc.plaintext
    )

    class Holder:
        read = gt.GT_GetSts

    assert Holder.read is gt.GT_GetSts
    assert Holder().read.__func__ is gt.GT_GetSts  # (a bound method, as a function gives)
    assert ctypes.POINTER(ctypes.c_long).__module__ == "ctypes"


def test_gtecat_centry_0_leaves_the_python_functions() -> None:
    """``GTECAT_CENTRY=0``: the public readers are the Python functions (read at import)."""
    code = "from gtecat import gt; import types; print(type(gt.GT_GetSts) is types.FunctionType)"
    env = {**os.environ, "GTECAT_CENTRY": "0"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert out.stdout.strip() == "True", out.stderr


@needs_cc
@pytest.mark.parametrize("bank", ["on", "off"])
def test_the_c_entry_answers_as_the_python_path_and_the_table(
    bank: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    _open(bank=bank)
    with_c = {n: _built(n, True, monkeypatch) for n in fast.READERS}
    without = {n: _built(n, False, monkeypatch) for n in fast.READERS}
    assert all(hasattr(f, "python") for f in with_c.values())
    assert not any(hasattr(f, "python") for f in without.values())
    bad = []
    for k, case in enumerate(_cases()):
        name, kind, t, axis, tail, core = case
        gtn = core is not None
        kw = k % 7 == 0
        got = [
            _call(with_c[name], gtn, case, kw),
            _call(without[name], gtn, case, kw),
        ]
        if gtn:  # the table's GTN_ twin
            o, p = _arg(kind, t)
            fn = getattr(gt, "GTN_" + name[3:]).__wrapped__
            args = (core, axis, p, *tail)
            rc = fn(*args[:-1], pClock=args[-1]) if kw and len(args) > 3 else fn(*args)
            got.append((rc, _shown(o), gt.GTE_GetLastError() if rc else ""))
        else:
            got.append(_call(with_c[name].slow, False, case, kw))
        if not got[0] == got[1] == got[2]:
            bad.append(f"{case} kw={kw}: C {got[0]}, Python {got[1]}, table {got[2]}")
    assert not bad, "\n".join(bad[:8])


@needs_cc
def test_the_c_entry_keeps_reference_counts() -> None:
    """Answered, handed on and refused calls leave every count as it was."""
    _open()
    s, d = ctypes.c_long(), ctypes.c_double()
    ps, pd = byref(s), byref(d)
    axis = 1 << 40  # (not a cached small int: its count shows)
    calls = [
        (gt.GT_GetSts, (1, ps), [s, ps]),
        (gt.GT_GetSts, (1, s, 1, None), [s]),
        (gt.GT_GetPrfPos, (1, pd, 1, 0), [d, pd]),
        (gt.GT_GetPrfPos, (1, d), [d]),
        (gt.GT_GetSts, (axis, ps), [axis, ps, s]),  # no such axis: the table's 7
        (gt.GT_GetSts, (1, byref(s, 4)), [s]),  # an offset: the Python path, the table
        (gt.GTN_GetSts, (1, 1, ps), [ps, s]),
        (gt.GTN_GetSts, (2, 1, ps), [ps, s]),
    ]
    for fn, args, watched in calls:
        for _ in range(5):
            fn(*args)
        before = [sys.getrefcount(x) for x in (*watched, *args)]
        for _ in range(50):
            fn(*args)
        assert [sys.getrefcount(x) for x in (*watched, *args)] == before, (fn, args)


@needs_cc
def test_a_value_the_object_cannot_hold_is_left_to_the_python_path() -> None:
    """A status word past a 32-bit object's range (latched flags made up here; the word has
    32 bits): the C entry leaves it to the Python path, whose answer it gives."""
    ctl = _open(bank="off")
    res = ctl.resources[1]
    for latched in (1 << 31, 1 << 40, -(1 << 31) - 1):
        res.latched = latched
        centry.changed()  # (the state changed by hand: the kept values ask again)
        got = []
        for call in (gt.GT_GetSts, gt.GT_GetSts.python):
            for t in (ctypes.c_int32, ctypes.c_long):
                o = t()
                rc = call(1, byref(o))
                got.append((rc, o.value, gt.GTE_GetLastError() if rc else ""))
        assert got[:2] == got[2:], (latched, got)
    res.latched = 0


#: the two-argument readers with a C entry: function -> first arguments to try
TWO_ARG = {
    **{n: [0, 3, 5, 6, 7, -1, 32, True, 1.0] for n in fast.IO_READERS},
    **{n: [1, 2, 3, 0, True, 1.0] for n in fast.ECAT_READERS},
    fast.HOMING: [1, 2, 3, 0, True, 1.0],
    **{n: [1, 2, 3, 0, True, 1.0] for n in fast.STRUCT_READERS},
    fast.HOME_STATUS: [1, 2, 3, 0, True, 1.0],
}
#: the structure readers among them: function -> their structure
STRUCTS = {
    **{n: v[0] for n, v in fast.STRUCT_READERS.items()},
    fast.HOME_STATUS: gt.THomeStatus,
}
TWO_ARG_TYPES = [
    ctypes.c_int32,
    ctypes.c_long,
    ctypes.c_int16,
    ctypes.c_uint16,
    ctypes.c_uint32,
    ctypes.c_ulong,
    ctypes.c_int8,
    ctypes.c_double,
]


def _two_arg_cases() -> list[tuple]:
    out = []
    for name, firsts in sorted(TWO_ARG.items()):
        types = [STRUCTS[name]] if name in STRUCTS else TWO_ARG_TYPES
        for kind in KINDS:
            if name in STRUCTS and kind in ("numpy", "field"):
                continue
            for t in types:
                for first in firsts:
                    for tail in [(), (1,), "kw"]:
                        out.append((name, kind, t, first, tail))
    if LONG:
        return out
    rnd = random.Random(31)
    common = [c for c in out if c[1] in ("byref", "reused", "obj") and c[4] == ()]
    return rnd.sample(common, 150) + rnd.sample(out, 250)


@needs_cc
def test_the_two_argument_readers_answer_as_their_python_path_and_the_table(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """GT_GetDi, GT_GetDiRaw, GT_GetDo, the PDO readers, the homing status, the Trap
    parameters and the smart homing's status: with the C entry, without it, and the table
    path."""
    _open()
    gt.GT_PrfTrap(2)  # (axis 2 in Trap: its parameters readable; axis 1 moving in Trap)
    built = {}
    for in_c in (True, False):
        monkeypatch.setattr(fast, "CENTRY", in_c)
        for name in TWO_ARG:
            slow = getattr(gt, name).slow
            built[name, in_c] = fast.FAST_MAKERS[name](name, slow, _core.SESSION, _core.advance)
    assert all(hasattr(built[n, True], "python") for n in TWO_ARG)
    bad = []
    for case in _two_arg_cases():
        name, kind, t, first, tail = case
        got = []
        for fn in (built[name, True], built[name, False], getattr(gt, name).slow):
            for _ in range(2):  # (the second call: with what the first one kept)
                o, p = _arg(kind, t)
                if tail == "kw":
                    rc = fn(first, **{fast_param(name): p})
                else:
                    rc = fn(first, p, *tail)
            got.append((rc, _shown(o), gt.GTE_GetLastError() if rc else ""))
        if not got[0] == got[1] == got[2]:
            bad.append(f"{case}: C {got[0]}, Python {got[1]}, table {got[2]}")
    assert not bad, "\n".join(bad[:8])


def fast_param(name: str) -> str:
    """The name of ``name``'s pointer parameter (a keyword call)."""
    from gtecat.gt.table import FUNCTIONS

    return FUNCTIONS[name].params[1].name


def _raw_buffers(size: int) -> list[tuple[str, Any]]:
    n = max(size, 1)
    return [
        ("c_ubyte", lambda: (o := (ctypes.c_ubyte * n)(*range(7, 7 + n)), o)),
        ("byref", lambda: (o := (ctypes.c_ubyte * n)(*range(7, 7 + n)), byref(o))),
        ("byref offset", lambda: (o := (ctypes.c_ubyte * (n + 1))(), byref(o, 1))),
        ("short", lambda: (o := (ctypes.c_ubyte * max(n - 1, 1))(), o)),
        ("c_int32", lambda: (o := (ctypes.c_int32 * n)(*range(n)), o)),
        ("c_void_p", lambda: (o := (ctypes.c_void_p * n)(), o)),
        ("bytearray", lambda: (o := bytearray(range(3, 3 + n)), o)),
        ("short bytearray", lambda: (o := bytearray(max(n - 1, 0)), o)),
        ("bytes", lambda: (o := bytes(range(3, 3 + n)), o)),
        ("numpy", lambda: (o := np.arange(n, dtype=np.uint8), o)),
        ("short numpy", lambda: (o := np.arange(max(n - 1, 0), dtype=np.uint8), o)),
        ("numpy int8", lambda: (o := np.arange(n, dtype=np.int8), o)),
        ("strided numpy", lambda: (o := np.arange(2 * n, dtype=np.uint8), o[::2])),
        ("read-only numpy", lambda: (o := np.arange(n, dtype=np.uint8), _read_only(o))),
        ("memoryview", lambda: (o := bytearray(range(5, 5 + n)), memoryview(o))),
        ("read-only memoryview", lambda: (o := bytes(range(5, 5 + n)), memoryview(o))),
        ("short memoryview", lambda: (o := bytearray(max(n - 1, 0)), memoryview(o))),
        ("memoryview of H", lambda: (o := bytearray(2 * n), memoryview(o).cast("H"))),
        ("c_long", lambda: (o := ctypes.c_long(5), o)),
    ]


def _read_only(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


@needs_cc
def test_the_raw_entries_answer_as_their_python_path_and_the_table(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """GT_Get/SetEcatRawData and GT_EcatIORead/WriteOutput with the C entry, without it, and
    the table path: each range of figure 5-2's image (and past it), each buffer kind; the
    buffer and the image alike afterwards."""
    ctl = _open()
    built = {}
    for in_c in (True, False):
        monkeypatch.setattr(fast, "CENTRY", in_c)
        for name in fast.RAW:
            slow = getattr(gt, name).slow
            built[name, in_c] = fast.fast_raw(name, slow, _core.SESSION, _core.advance)
    assert all(hasattr(built[n, True], "python") for n in fast.RAW)
    rnd = random.Random(32)
    bad = []
    cases = []
    for name in sorted(fast.RAW):
        io = name in ("GT_EcatIOReadInput", "GT_EcatIOWriteOutput")
        for offset in [-1, 0, 3, 6, 12, 30, 32, 38, 41, 44] if not io else [-1, 0, 1, 3, 6]:
            for size in (0, 1, 2, 4, 8, 11):
                for label, make in _raw_buffers(size):
                    for slave in [2, 0, 5, True] if io else [None]:
                        cases.append((name, offset, size, label, make, slave))
    if not LONG:
        cases = rnd.sample(cases, 400)
    for k, (name, offset, size, label, make, slave) in enumerate(cases):
        got = []
        for fn in (built[name, True], built[name, False], getattr(gt, name).slow):
            image = ctl.master.image.buffer
            image[:] = np.arange(len(image), dtype=np.uint8)  # (the same image for each)
            for _ in range(2):  # (the second call: with what the first one kept)
                o, p = make()
                args = (offset, size, p) if slave is None else (slave, offset, size, p)
                rc = fn(*args[:-1], pValue=p) if k % 9 == 0 else fn(*args)
            shown = bytes(o) if not isinstance(o, np.ndarray) else o.tobytes()
            got.append((rc, shown, bytes(image), gt.GTE_GetLastError() if rc else ""))
        if not got[0] == got[1] == got[2]:
            bad.append(f"{name}{(slave, offset, size, label)}: {[g[0::3] for g in got]}")
    assert not bad, "\n".join(bad[:8])


@needs_cc
def test_the_clock_answers_as_its_python_path_and_the_table(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """GT_GetClock(pClock[, pLoop]) with the C entry, without it, and the table path, a
    clock past what a 32-bit signed pClock holds included."""
    ctl = _open()
    built = {}
    for in_c in (True, False):
        monkeypatch.setattr(fast, "CENTRY", in_c)
        slow = gt.GT_GetClock.slow
        built[in_c] = fast.fast_clock(fast.CLOCK, slow, _core.SESSION, _core.advance)
    assert hasattr(built[True], "python")
    types = [ctypes.c_uint32, ctypes.c_int32, ctypes.c_ulong, ctypes.c_long, ctypes.c_int16]
    types.append(ctypes.c_double)
    bad = []
    for reset_ns in (ctl.reset_ns, ctl.clock.now_ns - (1 << 31) * 1_000_000):
        ctl.reset_ns = reset_ns
        for kind in KINDS:
            for t in types:
                for loop in [(), (None,), (0,), (1,), "byref", "kw"]:
                    got = []
                    for fn in (built[True], built[False], gt.GT_GetClock.slow):
                        o, p = _arg(kind, t)
                        loops = ctypes.c_uint32()
                        if loop == "kw":
                            rc = fn(pClock=p)
                        elif loop == "byref":
                            rc = fn(p, byref(loops))
                        else:
                            rc = fn(p, *loop)
                        err = gt.GTE_GetLastError() if rc else ""
                        got.append((rc, _shown(o), err, loops.value))
                    if not got[0] == got[1] == got[2]:
                        bad.append(f"{kind} {t.__name__} {loop}: {got}")
    assert not bad, "\n".join(bad[:8])


@needs_cc
def test_without_the_entry_type_the_entries_are_partials(monkeypatch: pytest.MonkeyPatch) -> None:
    """Where the callable type cannot be made, each entry is a ``functools.partial`` of its
    built-in function, tested and answering the same."""
    import functools

    def refuse() -> type:
        raise ValueError("no type here")

    monkeypatch.setattr(centry, "_callable_type", refuse)
    make, reason = centry._load()
    assert reason == "" and make is not None
    nope = object()
    fn = make(lambda *a, **k: "python", lambda n: 7, nope, [ctypes.c_long], centry.INT, False)
    s = ctypes.c_long()
    assert type(fn) is functools.partial
    assert (fn(1, byref(s)), s.value, fn(1, byref(s), 2)) == (0, 7, "python")


def test_a_pointer_to_memory_of_unproved_size_is_refused_not_written_through() -> None:
    """A ``POINTER(c_double)`` cast over 2 bytes at the end of a mapped page (reading
    or writing 8 there would crash the process), over numpy float32s (``data_as``), or over
    a bare address: the manual's 7 with the table path's reason, the memory untouched;
    ``pointer(x)`` itself is still answered."""
    import mmap

    _open()
    page = mmap.mmap(-1, mmap.PAGESIZE)
    end = (ctypes.c_ubyte * 2).from_buffer(page, mmap.PAGESIZE - 2)
    f32 = np.zeros(3, np.float32)
    held = ctypes.c_double(-1.0)
    try:
        for fn in (gt.GT_GetPrfPos, gt.GT_GetEncPos):
            for p in (
                ctypes.cast(end, ctypes.POINTER(ctypes.c_double)),
                f32.ctypes.data_as(ctypes.POINTER(ctypes.c_double)),
                ctypes.cast(ctypes.addressof(held), ctypes.POINTER(ctypes.c_double)),
            ):
                assert fn(1, p) == 7, gt.GTE_GetLastError()
                assert "pValue" in gt.GTE_GetLastError()
        assert bytes(end) == b"\0\0" and not f32.any() and held.value == -1.0
        assert gt.GT_GetSts(1, ctypes.cast(end, ctypes.POINTER(ctypes.c_long))) == 7
        # pointer(y) of a narrower y cast to a wider pointer type (the cast keeps y)
        narrow = ctypes.c_int16.from_buffer(page, mmap.PAGESIZE - 4)
        wide = ctypes.cast(ctypes.pointer(narrow), ctypes.POINTER(ctypes.c_double))
        assert gt.GT_GetPrfPos(1, wide) == 7 and narrow.value == 0
        as_long = ctypes.cast(ctypes.pointer(narrow), ctypes.POINTER(ctypes.c_long))
        assert gt.GT_GetSts(1, as_long) == 7
        assert gt.GT_GetPrfPos(1, ctypes.pointer(held)) == 0 and held.value > 0.0
    finally:
        gt.GT_Close()  # (the page is unmapped when nothing holds it)


@needs_cc
def test_an_argument_changed_while_the_value_is_made_is_looked_at_again() -> None:
    """The value function is Python, so another thread (or a collector callback) may
    re-point a pointer (freeing its old object) or resize a bytearray (freeing its old
    buffer) while it runs: the entry writes where the argument points after it, never into
    the freed memory (objects made meanwhile keep their values)."""
    p = ctypes.pointer(ctypes.c_double(-1.0))
    victims: list[Any] = []

    def repointing(n: Any) -> Any:
        p.contents = ctypes.c_double(-2.0)  # (the old object freed here)
        victims.extend(ctypes.c_double(-3.0) for _ in range(50))
        return 400.0

    entry = centry.reader(
        lambda *a: -1, repointing, _core, [ctypes.c_double], centry.DOUBLE, pointers=True
    )
    assert entry(1, p) == 0
    assert p.contents.value == 400.0 and all(v.value == -3.0 for v in victims)

    image = (ctypes.c_ubyte * 16)(*range(16))
    ba = bytearray(b"\xee" * 4096)
    held: list[bytearray] = []

    def resizing(offset: int, size: int, tp: Any) -> bytes:
        ba.extend(bytes(1 << 20))  # (the old buffer freed here)
        held.append(bytearray(b"\x55" * 4096))
        return centry.runs([(0, ctypes.addressof(image), size)])

    entry = centry.raw(lambda *a: -1, resizing, _core, io=False, write=False)
    assert entry(0, 16, ba) == 0
    assert ba[:16] == bytes(range(16)) and held[0] == bytearray(b"\x55" * 4096)

    shrinking = centry.raw(
        lambda *a: -1,
        lambda offset, size, tp: (ba.clear(), centry.runs([(0, 1, size)]))[1],
        _core,
        io=False,
        write=False,
    )
    assert shrinking(0, 16, ba) == -1  # (too small now: handed on, nothing copied)
