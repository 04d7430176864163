"""Fuzz GT functions from the function table, in a child process.

``python -m tests.gtecat.gt.fuzz_table_worker [--examples N] [--twin-examples M] NAME...``
brings up the manual's figure 5-2 bus in lockstep clock and, for each named function (``GT_*``, its
``GTN_*`` twin, ``GTE_*``), runs a hypothesis test that calls it with arguments
generated from the table's parameter types - good ones, and bad ones: integers outside
the C type, floats where integers belong, nan/inf, None, text, containers, NULL and
typed NULL pointers, raw addresses, too-small, zero-length, wrong-width, offset and
cast pointers, structures of the wrong type, extra and unknown arguments, bad cores.

Each call must return a plain int among the manual's codes (never -7, an internal
error), raise nothing, finish within a few seconds, write nothing outside the memory
its pointer arguments own (canary bytes around every ctypes object it is given) and
nothing into ``in`` pointers, return 7 and write nothing at all when an argument is
certainly illegal, and leave the bus answering.  It runs in a child process
(``test_fuzz_table.py``) so a crash or a hang fails one batch with its output instead
of the test run.  Output: one ``ok``/``FAIL`` line per function (with the failing
example), ``WARN`` lines for non-zero returns without a recorded reason, and exit
status 0 only when every function passed.  ``CI`` in the environment derandomises.
"""

from __future__ import annotations

import argparse
import ctypes
import logging
import math
import os
import shutil
import signal
import sys
import tempfile
import time
import traceback
from ctypes import POINTER, byref, c_char_p, c_ubyte, c_void_p, cast, create_string_buffer
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import HealthCheck, given, note, settings
from hypothesis import strategies as st

from gtecat import gt
from gtecat.gt import _core
from gtecat.gt.args import _struct_types, shown
from gtecat.gt.table import ENUMS, NO_CORE_TWINS, SAME_PARAM_TWINS, SCALARS, Param
from tests.conftest import EXAMPLES
from tests.gtecat.gt.conftest import bring_up

ALLOWED = {0, 1, 7, -1, -6}
#: codes chapter 13 gives some functions besides table 3-1
OWN_CODES = {
    "InitEcatComm": {-8, -9, -10},  # entry 79
    "Download": {2007, 2008},  # entry 10
    "GetFunId": {2007, 2008},  # entry 52
    "GetVarId": {2007, 2008},  # entry 75
    "NetInit": {11702, 11902},  # the vendor's network codes (gtecat.gt.net_init_calls)
}
#: functions that may legitimately take the bus down (restored after each call)
STATEFUL = {
    "Open",
    "OpenCard",
    "NetInit",
    "Close",
    "Reset",
    "InitEcatComm",
    "StartEcatComm",
    "TerminateEcatComm",
    "LoadConfig",
    "UnplugSlave",
    "ReplugSlave",
    "SetCardNo",  # every later call addresses another card
    "SetCore",  # every later GT_ call addresses another core
}
CALL_TIMEOUT_S = 10.0
PAD = 16
CONFIGS = [Path("servo.cfg"), Path("test.cfg")]  # copied into the scratch directory

CTYPE = {k: getattr(ctypes, v[0]) for k, v in SCALARS.items()}
ALT_CTYPE = {"long": ctypes.c_int32, "unsigned long": ctypes.c_uint32}
#: memory of the other kind of number: refused (C would not compile it)
OTHER_KIND = {"double": ctypes.c_long, "float": ctypes.c_long}
#: every numpy dtype kind a caller may hand over (numbers, and what is not numbers)
NP_DTYPES = [
    np.int8, np.uint8, np.int16, np.uint16, np.int32, np.uint32, np.int64, np.uint64,
    np.float16, np.float32, np.float64, np.complex128, np.bool_, ">i4", "<f8",
    "S4", "U2", "V4", "M8[s]", "m8[s]", [("a", "<i4"), ("b", "<f8")],
]  # fmt: skip
#: the numpy dtype of each scalar type of the table (the vendor's ``long`` is 32 bits; ``char``
#: a number, not a byte string)
NPTYPE = {
    **{k: np.dtype(getattr(ctypes, v[0])).type for k, v in SCALARS.items()},
    "char": np.int8,
    "long": np.int32,
    "unsigned long": np.uint32,
}
STRUCTS = _struct_types()


class Hang(BaseException):
    """A call ran past CALL_TIMEOUT_S (BaseException: the GT layer must not swallow it)."""


def _on_alarm(signum: int, frame: Any) -> None:
    raise Hang


# --- health of the bus --------------------------------------------------------------------------
def healthy() -> str:
    """'' when the bus answers, else what failed."""
    sts = ctypes.c_long()
    if (rc := gt.GT_GetSts(1, byref(sts))) != 0:
        return f"GT_GetSts(1) -> {rc}: {gt.GTE_GetLastError()}"
    buf = (c_ubyte * 4)()
    if (rc := gt.GT_GetEcatRawData(0, 4, buf)) != 0:
        return f"GT_GetEcatRawData(0, 4) -> {rc}: {gt.GTE_GetLastError()}"
    if (rc := gt.GTE_Wait(2)) != 0:  # let cycles run: what the call set up must not break them
        return f"GTE_Wait(2) -> {rc}: {gt.GTE_GetLastError()}"
    ready = ctypes.c_short()
    if gt.GT_IsEcatReady(byref(ready)) != 0 or ready.value != 1:
        return f"GT_IsEcatReady -> status {ready.value}: {gt.GTE_GetLastError()}"
    return ""


def restart() -> None:
    from gtecat.gt import _core

    _core.close_all()  # every card, and card 0 current again
    bring_up(clock="lockstep")


# --- guarded memory ------------------------------------------------------------------------------
class Guard:
    """A ctypes object placed inside a bytearray with canary bytes before and after."""

    def __init__(self, ctype: Any, content: bytes | None, writable: bool, legal: int = 0) -> None:
        size = ctypes.sizeof(ctype)
        body = content if content is not None else bytes(size)
        self.buf = bytearray(b"\xa5" * PAD + body[:size].ljust(size, b"\0") + b"\x5a" * PAD)
        self.obj = ctype.from_buffer(self.buf, PAD)
        self.before = bytes(self.buf)
        self.lo, self.hi = PAD + legal, PAD + size  # where the call may write
        self.writable = writable

    def check(self, untouched: bool) -> str:
        now = bytes(self.buf)
        if now[: self.lo] != self.before[: self.lo] or now[self.hi :] != self.before[self.hi :]:
            return f"wrote outside the object ({self.before.hex()} -> {now.hex()})"
        if (untouched or not self.writable) and now != self.before:
            return f"wrote into memory it must not touch ({self.before.hex()} -> {now.hex()})"
        return ""


class Arg:
    """One generated argument: the value and what the test knows about it."""

    __slots__ = ("bad", "cap", "desc", "guards", "value")

    def __init__(
        self, value: Any, desc: str, *, bad: bool = False, cap: int | None = None, guards=()
    ):
        self.value, self.desc, self.bad, self.cap, self.guards = value, desc, bad, cap, guards


# --- scalars -------------------------------------------------------------------------------------
def int_range(p: Param) -> tuple[int, int]:
    _, lo, hi, _ = SCALARS["int" if p.ctype in ENUMS else p.ctype]  # a C enum is an int
    if p.mask:
        lo, hi = min(lo, -(1 << 31)), max(hi, (1 << 32) - 1)
    if p.lo is not None:
        lo, hi = max(lo, math.ceil(p.lo)), min(hi, math.floor(p.hi))  # type: ignore[arg-type]
    return lo, hi


def good_int(data: Any, p: Param, is_count: bool) -> tuple[Any, int]:
    lo, hi = int_range(p)
    small = st.integers(max(lo, 0 if is_count else -1), min(hi, 6 if is_count else 9))
    v = data.draw(
        st.one_of(small, small, st.integers(lo, hi), st.sampled_from([lo, hi])), label=p.name
    )
    wrap = data.draw(st.sampled_from(["int", "int", "numpy", "ctypes", "bool"]))
    if wrap == "numpy":
        return (np.uint64(v) if v >= 0 else np.int64(v)), v
    if wrap == "ctypes":
        return ctypes.c_longlong(v), v
    if wrap == "bool" and v in (0, 1):
        return bool(v), v
    return v, v


def bad_int(data: Any, p: Param) -> Any:
    lo, hi = int_range(p)
    return data.draw(
        st.one_of(
            st.integers(hi + 1, hi + (1 << 70)),
            st.integers(lo - (1 << 70), lo - 1),
            st.sampled_from([1 << 64, -(1 << 63) - 1, hi + 1, lo - 1]),
            st.floats(),
            st.sampled_from(
                [
                    None,
                    "1",
                    b"\x01",
                    [1],
                    (1,),
                    {},
                    np.array([1]),
                    np.array(1),
                    np.array([1], dtype=object),
                    10**5000,  # beyond what int() and repr() convert to text by default
                    -(10**5000),
                    np.float64(1.0),
                    ctypes.c_double(1.0),
                    1 + 0j,
                    object(),
                    c_char_p(b"1"),
                ]
            ),
        ),
        label=p.name,
    )


def good_real(data: Any, p: Param, fname: str) -> Any:
    if fname.endswith("_Wait"):
        v = data.draw(st.one_of(st.floats(0, 3), st.integers(0, 3)), label=p.name)
    elif p.lo is not None:
        v = data.draw(st.floats(p.lo, p.hi), label=p.name)
    else:
        v = data.draw(
            st.one_of(
                st.floats(-1e3, 1e3),
                st.floats(allow_nan=False, allow_infinity=False),
                st.integers(-1000, 1000),
                st.sampled_from([0.0, -0.0, 5e-324, 1.7976931348623157e308]),
            ),
            label=p.name,
        )
    wrap = data.draw(st.sampled_from(["py", "py", "numpy", "ctypes"]))
    if wrap == "numpy":
        return np.float64(v)
    if wrap == "ctypes":
        return ctypes.c_double(v)
    return v


def bad_real(data: Any, p: Param) -> Any:
    choices = [
        math.nan,
        math.inf,
        -math.inf,
        None,
        "1.0",
        b"",
        [1.0],
        1 + 0j,
        object(),
        10**400,
        10**5000,
        np.array([1.0]),
        np.array(1.0, dtype=object),
        np.float64("nan"),
        ctypes.c_double(math.inf),
    ]
    if p.lo is not None:
        choices += [p.lo - 1, p.hi + 0.5, float(1 << 64), 1 << 64, -1e300, 1e300]
    return data.draw(st.sampled_from(choices), label=p.name)


# --- pointers ------------------------------------------------------------------------------------
def pointer_arg(data: Any, p: Param, n: int, good: bool) -> Arg:
    """A pointer argument for ``p`` when the call moves ``n`` elements (0: unknown)."""
    writable = p.direction != "in"
    if p.text and p.direction == "in":
        return text_arg(data, p, good)
    if p.is_struct:
        T: Any = STRUCTS[p.ctype]
        kind = "struct"
    elif p.ctype in ("unsigned char", "char") or p.text:
        T, kind = c_ubyte, "bytes"
    else:
        T, kind = CTYPE[p.ctype], "num"
    s = ctypes.sizeof(T)
    if kind == "struct":
        a = 1
    elif p.text:
        a = data.draw(st.sampled_from([p.count, p.count + 8, 48]))  # outstr[64]
    elif 1 <= n <= 4096:
        a = n + data.draw(st.integers(0, 3))
    elif n == 0:
        a = data.draw(st.integers(1, 16))
    else:
        a = 16
    content = None if writable else data.draw(st.binary(min_size=a * s, max_size=a * s))

    def guard(ctype: Any, legal: int = 0) -> Guard:
        return Guard(ctype, content, writable, legal)

    def numeric(obj_elem: Any, nbytes: int, elems: int | None = None) -> int:
        """capacity as the binder counts it."""
        if kind == "bytes":
            return nbytes
        if elems is not None:
            return elems
        return nbytes // ctypes.sizeof(obj_elem)

    form = data.draw(st.sampled_from(GOOD_FORMS if good else BAD_FORMS), label=f"{p.name} form")
    nullable = p.optional
    if form == "array":
        g = guard(T * a)
        return Arg(g.obj, f"({T.__name__}*{a})()", cap=numeric(T, a * s), guards=(g,))
    if form == "byref":
        g = guard(T * a) if a > 1 else guard(T)
        return Arg(byref(g.obj), f"byref({T.__name__}[{a}])", cap=numeric(T, a * s), guards=(g,))
    if form == "pointer":
        if a == 1 and kind != "struct":
            g = guard(T)
            return Arg(ctypes.pointer(g.obj), f"pointer({T.__name__}())", cap=1, guards=(g,))
        g = guard(T * a)
        return Arg(
            cast(g.obj, POINTER(T)), f"cast(({T.__name__}*{a})(), POINTER)", cap=a, guards=(g,)
        )
    if form == "offset":
        k = data.draw(st.integers(1, 3))
        g = guard(T * (a + k), legal=k * s)
        return Arg(
            byref(g.obj, k * s),
            f"byref(({T.__name__}*{a + k})(), {k * s})",
            cap=numeric(T, a * s),
            guards=(g,),
        )
    if form == "struct_self" and kind == "struct":
        g = guard(T)
        return Arg(g.obj, f"{T.__name__}()", guards=(g,))
    if form == "list":
        vals = [0] * a if writable else list((content or b"")[:a])
        return Arg(vals, f"[{a} ints]", cap=a)
    if form == "numpy" and kind != "struct":
        dt = NPTYPE["unsigned char" if kind == "bytes" else p.ctype]
        arr = np.zeros(a, dtype=dt)
        return Arg(
            arr, f"np.zeros({a}, {dt.__name__})", cap=a * arr.itemsize if kind == "bytes" else a
        )
    if form == "bytearray":
        b = bytearray(content or bytes(a * s))
        return Arg(b, f"bytearray({a * s})", cap=numeric(c_ubyte, a * s, elems=a * s))
    if form == "string_buffer":
        b = create_string_buffer(a * s)
        return Arg(b, f"create_string_buffer({a * s})", cap=numeric(ctypes.c_char, a * s))
    if form == "alt_type":
        alt = ALT_CTYPE.get(p.ctype, T if kind == "num" else ctypes.c_char)
        if kind == "struct":
            alt = c_ubyte * s  # same size, not the structure type
        g = Guard(alt * a, content, writable)
        return Arg(
            byref(g.obj),
            f"byref(({alt.__name__}*{a})())",
            cap=numeric(alt, a * ctypes.sizeof(alt)),
            guards=(g,),
        )
    if form == "bytes" and not writable:
        return Arg(
            bytes(content or b""), f"bytes({a * s})", cap=numeric(c_ubyte, a * s, elems=a * s)
        )
    # --- bad forms (or forms that do not fit this parameter) ---
    if form == "null":
        v = data.draw(st.sampled_from([None, 0, False, POINTER(T)(), c_void_p(), c_char_p()]))
        return Arg(v, f"NULL {v!r}", bad=not nullable)
    if form == "raw_address":
        g = guard(T * a)
        v = data.draw(st.sampled_from([ctypes.addressof(g.obj), -1, 1 << 70, 4096]))
        return Arg(v, f"raw address {v}", bad=True, guards=(g,))
    if form == "one_byte":
        g = Guard(c_ubyte, None, writable)
        v = data.draw(st.sampled_from([ctypes.pointer(g.obj), byref(g.obj)]))
        # for bytes too small beyond one; a numeric value is stored truncated (memory-safe)
        return Arg(v, "pointer(c_ubyte())", cap=1, guards=(g,))
    if form == "zero_length":
        g = Guard(T * 0, None, writable)
        return Arg(g.obj, f"({T.__name__}*0)()", cap=0, guards=(g,))
    if form == "past_end":
        g = guard(T * a)
        off = data.draw(st.sampled_from([a * s, a * s + s, a * s + 4096]))
        return Arg(
            byref(g.obj, off), f"byref(arr[{a}], {off})", bad=off > a * s, cap=0, guards=(g,)
        )
    if form == "unowned_cast":
        x = (T * a)()
        v = cast(c_void_p(ctypes.addressof(x)), POINTER(T))
        return Arg(v, "cast(c_void_p(addr), POINTER)", bad=True, guards=())
    if form == "void_p":
        x = (T * a)()
        return Arg(c_void_p(ctypes.addressof(x)), "c_void_p(addr)", bad=True)
    if form == "char_p":
        return Arg(c_char_p(b"abc"), "c_char_p(b'abc')", bad=True)
    if form == "wrong_struct":
        other = data.draw(st.sampled_from(sorted(STRUCTS)))
        g = Guard(STRUCTS[other], None, writable)
        W = STRUCTS[other]
        return Arg(
            byref(g.obj),
            f"byref({other}())",
            cap=numeric(W, ctypes.sizeof(W), elems=1),
            guards=(g,),
        )
    if form == "bytes_out" and writable:
        return Arg(bytes(a * s), "bytes (read-only)", bad=True)
    if form == "readonly_numpy" and writable:
        arr = np.zeros(a, dtype=np.uint8 if kind == "bytes" else np.int64)
        arr.flags.writeable = False
        return Arg(arr, "read-only numpy array", bad=True)
    if form == "strided_numpy":
        arr = np.zeros(2 * a + 2, dtype=np.float64)[::2]
        return Arg(arr, "non-contiguous numpy array", bad=True)
    if form == "narrow_numpy" and kind == "num":
        arr = np.zeros(a, dtype=np.int8)
        return Arg(arr, "np.int8 array (narrow)", cap=a)
    if form == "other_kind" and kind == "num":
        other = OTHER_KIND.get(p.ctype, ctypes.c_double)
        g = Guard(other * a, content, writable)
        return Arg(byref(g.obj), f"byref(({other.__name__}*{a})())", bad=True, guards=(g,))
    if form == "object_numpy":
        arr = np.zeros(max(a * s, 1), dtype=object)
        return Arg(arr, "numpy array of objects", bad=True)
    if form == "any_numpy":
        dt = np.dtype(data.draw(st.sampled_from(NP_DTYPES), label="dtype"))
        arr = np.zeros(max(a * s // dt.itemsize, 1) + data.draw(st.integers(0, 2)), dtype=dt)
        if data.draw(st.booleans(), label="2-d"):
            arr = arr.reshape(1, -1)
        return Arg(arr, f"np.zeros({arr.shape}, {dt})")  # works or 7, never worse
    if form == "strided_memoryview":
        b = bytearray(2 * a * s + 2)
        return Arg(memoryview(b)[::2], "memoryview(bytearray)[::2]", bad=True)
    if form == "memoryview":
        fmt = data.draw(st.sampled_from(["B", "b", "h", "i", "l", "q", "d", "f", "?", "c"]))
        b = bytearray(a * 8 + 8)
        mv = memoryview(b).cast(fmt) if fmt != "B" else memoryview(b)
        if data.draw(st.booleans(), label="2-d"):
            n = mv.nbytes // mv.itemsize
            mv = mv[: n - n % 2].cast("B").cast(fmt, shape=[2, n // 2]) if n >= 2 else mv
        return Arg(mv, f"memoryview format {fmt} shape {mv.shape}")  # works or 7
    if form == "huge_ints":
        return Arg([10**5000] * a, "list of 5001-digit integers")  # 7 where it is read
    if form == "list_of_text":
        return Arg(["x"] * a, "list of str", cap=a)
    if form == "junk":
        v = data.draw(st.sampled_from(["abc", 1.5, math.nan, {}, (1, 2), object(), 1 + 2j]))
        return Arg(v, f"junk {v!r}", bad=True)
    g = guard(T * a)  # a form that does not fit: a plain good array
    return Arg(g.obj, f"({T.__name__}*{a})()", cap=numeric(T, a * s), guards=(g,))


GOOD_FORMS = [
    "array",
    "byref",
    "pointer",
    "offset",
    "struct_self",
    "list",
    "numpy",
    "bytearray",
    "string_buffer",
    "alt_type",
    "bytes",
]
BAD_FORMS = [
    "null",
    "raw_address",
    "one_byte",
    "zero_length",
    "past_end",
    "unowned_cast",
    "void_p",
    "char_p",
    "wrong_struct",
    "bytes_out",
    "readonly_numpy",
    "strided_numpy",
    "narrow_numpy",
    "other_kind",
    "object_numpy",
    "any_numpy",
    "strided_memoryview",
    "memoryview",
    "huge_ints",
    "list_of_text",
    "junk",
]


def text_arg(data: Any, p: Param, good: bool) -> Arg:
    if good:
        cfg = data.draw(st.sampled_from(CONFIGS))
        v = data.draw(
            st.one_of(
                st.sampled_from(
                    [
                        str(cfg),
                        str(cfg).encode(),
                        cfg,
                        c_char_p(str(cfg).encode()),
                        create_string_buffer(str(cfg).encode()),
                        str(cfg) + "\0junk",
                    ]
                ),
                st.text(max_size=12).map(lambda t: str(Path("/nonexistent") / t)),
                st.text(max_size=12),
            ),
            label=p.name,
        )
        return Arg(v, f"text {v!r}")
    v = data.draw(st.sampled_from([None, 123, 1.5, [b"x"], {}, object(), "x" * 5000]), label=p.name)
    if v is None and p.optional:
        return Arg(v, "None")
    return Arg(v, f"bad text {v!r:.40}", bad=True)


# --- one function --------------------------------------------------------------------------------
def _short(v: Any) -> str:
    return shown(v, 80)


#: anything a caller might pass to a declared-only function (it looks at none of it)
_ANYTHING = st.one_of(
    st.integers(-(1 << 70), 1 << 70),
    st.floats(),
    st.none(),
    st.text(max_size=8),
    st.binary(max_size=8),
    st.builds(lambda v: ctypes.byref(ctypes.c_short(v)), st.integers(-(1 << 15), (1 << 15) - 1)),
    st.builds(lambda n: (ctypes.c_double * n)(), st.integers(0, 4)),
    st.builds(lambda n: create_string_buffer(n), st.integers(0, 16)),
    st.just(gt.TTrapPrm()),
)


def fuzz_declared(name: str, examples: int) -> None:
    """A declared-only function (gtecat.gt.declared): whatever it is given - any number of
    arguments of any kind, keywords - it returns CMD_DECLARED (8) with its reason, writes
    nothing, never raises, and the bus stays up."""
    fn = getattr(gt, name)
    n_params = len(fn.prototype.params)

    def example(data: Any) -> None:
        args = data.draw(st.lists(_ANYTHING, max_size=n_params + 2), label="args")
        kwargs = data.draw(
            st.dictionaries(st.sampled_from(["core", "axis", "zz"]), _ANYTHING, max_size=2),
            label="kwargs",
        )
        snapshot = [bytes(a) if isinstance(a, ctypes.Array) else None for a in args]
        try:
            rc = fn(*args, **kwargs)
        except BaseException as e:
            raise AssertionError(f"{name}: exception escaped: {e!r}") from e
        assert rc == _core.CMD_DECLARED, f"{name} returned {rc!r}"
        reason = gt.GTE_GetLastError()
        assert reason.startswith(f"{name} returned 8: {name} is declared but not emulated"), reason
        for a, before in zip(args, snapshot, strict=True):
            if before is not None:
                assert bytes(a) == before, f"{name} wrote into an argument"

    @settings(
        max_examples=examples,
        deadline=None,
        database=None,
        derandomize=bool(os.environ.get("CI")),
        suppress_health_check=list(HealthCheck),
        print_blob=False,
    )
    @given(st.data())
    def run(data: Any) -> None:
        example(data)

    run()
    problem = healthy()
    assert not problem, f"after {name}: the bus no longer answers: {problem}"


def fuzz_function(name: str, examples: int, warnings: set[str]) -> None:
    fn = getattr(gt, name)
    if getattr(fn, "declared", False):
        fuzz_declared(name, min(examples, 8))
        return
    proto = fn.prototype
    # GTN_Open(channel, param) / GTN_Close(): the vendor's GTN header gives them no core
    no_core = name.startswith("GTN_") and (
        "GT_" + name[4:] in NO_CORE_TWINS or "GT_" + name[4:] in SAME_PARAM_TWINS
    )
    # a GTN_x line of its own that names its core (GTN_PosCompareSpace(core, ...)): the
    # table's parameters already hold it
    own_core = bool(proto.params) and proto.params[0].name == "core"
    # a GTN_x line of its own without a core (GTN_OpenCard(channel, ...)): called as written
    own_line = proto.name == name and name.startswith("GTN_")
    is_gtn = name.startswith("GTN_") and not no_core and not own_core and not own_line
    base = name.partition("_")[2]
    params = list(proto.params)
    names = [p.name for p in params]
    counted_by = {p.count: p for p in params if p.pointer and isinstance(p.count, str)}
    has_default = [p.default is not None or (p.pointer and p.optional) for p in params]
    n_trailing = 0
    for d in reversed(has_default):
        if not d:
            break
        n_trailing += 1
    codes = ALLOWED | OWN_CODES.get(base, set())

    def example(data: Any) -> None:
        mode = data.draw(st.sampled_from(["good", "good", "bad_one", "chaos"]), label="mode")
        form = data.draw(
            st.sampled_from(["pos", "pos", "kw", "omit", "extra", "unknown_kw", "dup_kw"]),
            label="form",
        )
        omitted = data.draw(st.integers(0, n_trailing)) if form == "omit" else 0
        passed = len(params) - omitted
        bad_flags = [False] * len(params)
        if mode == "bad_one" and passed:
            bad_flags[data.draw(st.integers(0, passed - 1), label="bad index")] = True
        elif mode == "chaos":
            bad_flags = [data.draw(st.booleans()) for _ in params]
        must7 = False
        values: list[Any] = []
        eff: dict[str, Any] = {}
        args_info: list[Arg | None] = [None] * len(params)
        for i, p in enumerate(params):  # scalars first: pointers are sized by them
            if p.pointer:
                continue
            if i >= passed:
                eff[p.name] = p.default_value()
                continue
            if bad_flags[i]:
                v = bad_real(data, p) if p.is_float else bad_int(data, p)
                must7 = True
                args_info[i] = Arg(v, _short(v), bad=True)
            elif p.is_float:
                v = good_real(data, p, name)
                args_info[i] = Arg(v, _short(v))
            else:
                v, eff[p.name] = good_int(data, p, p.name in counted_by)
                args_info[i] = Arg(v, _short(v))
        for i, p in enumerate(params):
            if not p.pointer or i >= passed:
                continue
            if p.text and p.direction == "in":
                n = 0
            elif isinstance(p.count, str):
                c = eff.get(p.count)
                n = c if isinstance(c, int) else 0
            else:
                n = p.count
            arg = pointer_arg(data, p, n, not bad_flags[i])
            if arg.bad:
                must7 = True
            elif (
                arg.cap is not None
                and n >= 1
                and arg.cap < n
                and not p.is_struct
                and not p.text
                and not (isinstance(arg.value, list) and p.direction == "out")
            ):
                must7 = True  # too small for what the call moves: the binder refuses it
            args_info[i] = arg
        values = [a.value for a in args_info[:passed]]  # type: ignore[union-attr]
        args: list[Any] = list(values)
        kwargs: dict[str, Any] = {}
        if form == "kw" and passed:
            j = data.draw(st.integers(0, passed), label="first keyword")
            args, kwargs = values[:j], {names[k]: values[k] for k in range(j, passed)}
        elif form == "extra":
            # one argument more is still a form the function takes where the core may come
            # first (manual 5.2.2.5; GTN_Open/GTN_Close of earlier gtecat releases): two more
            args += [0, 0] if proto.core_first_form or no_core else [0]
            must7 = True
        elif form == "unknown_kw":
            kwargs["zz_no_such_parameter"] = 1
            must7 = True
        elif form == "dup_kw" and passed:
            kwargs[names[0]] = values[0]
            must7 = True
        core_desc = ""
        if is_gtn:
            core_mode = data.draw(
                st.sampled_from(["one", "one", "numpy", "ctypes", "kw", "missing", "bad"]),
                label="core",
            )
            if core_mode == "bad":
                core = data.draw(
                    # core 2 exists (the card's second core): 3 is the first that does not
                    st.sampled_from(["1", 1.0, None, 1 << 40, -(1 << 40), 0, 3, -1, math.nan])
                )
                must7 = True
            else:
                core = {"numpy": np.int16(1), "ctypes": ctypes.c_short(1)}.get(core_mode, 1)
            if core_mode in ("kw", "missing") and form in ("extra", "dup_kw"):
                core_mode = "one"  # both need positional arguments
            if core_mode in ("kw", "missing"):
                kwargs.update({names[k]: args[k] for k in range(len(args))})
                args = []
                if core_mode == "kw":
                    kwargs["core"] = 1
                else:
                    must7 = True
                core_desc = f"{core_mode} core"
            else:
                args = [core, *args]
                core_desc = f"core={core!r}"
        elif no_core and form == "pos" and passed == len(params) and params:
            # the core-first form of earlier gtecat releases: one argument more than the vendor's
            if data.draw(st.booleans(), label="earlier core-first form"):
                core = data.draw(st.sampled_from([1, 1, 3, "1"]))  # core 2 exists
                args = [core, *args]
                must7 = must7 or core != 1
                core_desc = f"core first={core!r}"
        elif proto.core_first_form and form in ("pos", "omit") and passed == len(params):
            if data.draw(st.booleans(), label="core first (manual 5.2.2.5)"):
                core = data.draw(st.sampled_from([1, 1, 3, "1"]))  # core 2 exists
                args = [core, *args]
                must7 = must7 or core != 1
                core_desc = f"core first={core!r}"
        desc = (
            f"{name}({', '.join(a.desc for a in args_info[:passed] if a)}) "
            f"form={form} {core_desc} kwargs={sorted(kwargs)}"
        )
        note(desc)
        last = _core.SESSION.errors[-1] if _core.SESSION.errors else None
        signal.setitimer(signal.ITIMER_REAL, CALL_TIMEOUT_S)
        # the call's own CPU time: on a loaded machine its wall time is whatever share of a
        # CPU this process got (a call that blocks is the wall-clock alarm's to catch)
        t0 = time.process_time()
        try:
            rc = fn(*args, **kwargs)
        except Hang:
            raise AssertionError(f"hang (> {CALL_TIMEOUT_S} s): {desc}") from None
        except BaseException as e:
            raise AssertionError(f"exception escaped: {desc}: {e!r}") from e
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
        took = time.process_time() - t0
        reason = gt.GTE_GetLastError()
        assert type(rc) is int, f"{desc}: returned {rc!r} ({type(rc).__name__}), not an int"
        assert rc != -7, f"{desc}: internal error -7: {reason}"
        assert rc in codes, f"{desc}: returned {rc}, not a manual code: {reason}"
        if must7:
            assert rc == 7, f"{desc}: an illegal argument must give 7, got {rc} ({reason})"
        if rc != 0:
            now = _core.SESSION.errors[-1] if _core.SESSION.errors else None
            if now is last:
                warnings.add(f"{base}: returned {rc} without a reason ({desc})")
        for a in args_info:
            for g in a.guards if a else ():
                problem = g.check(untouched=must7)
                assert not problem, f"{desc} -> {rc}: {problem}"
        assert took < 2.0, f"{desc}: took {took:.2f} s of CPU"
        if base in STATEFUL:
            if (rc == 0 and base in ("UnplugSlave", "Close")) or healthy():
                restart()
        problem = healthy()
        assert not problem, f"{desc} -> {rc}: the bus no longer answers: {problem}"

    # the hypothesis test is this one-line wrapper, not ``example`` itself: hypothesis hashes
    # the source of the test it runs (for its database key and the derandomised seed) once
    # per function, and tokenizing the long body 2 x 376 times was half of the fuzzer's time
    @settings(
        max_examples=examples,
        deadline=None,
        database=None,
        derandomize=bool(os.environ.get("CI")),
        suppress_health_check=list(HealthCheck),
        print_blob=False,
    )
    @given(st.data())
    def run(data: Any) -> None:
        example(data)

    if healthy():
        restart()
    run()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--examples", type=int, default=20, help="per GT_/GTE_ function")
    ap.add_argument("--twin-examples", type=int, default=10, help="per GTN_ twin")
    ap.add_argument("--verbose", action="store_true", help="show the GT layer's log")
    ap.add_argument("names", nargs="+")
    a = ap.parse_args(argv)
    signal.signal(signal.SIGALRM, _on_alarm)
    # whatever the calls write (GT_Compile's .bin/.ini, Gecat.mram, paths made up by the
    # fuzzer) lands in a scratch directory, never in the checkout
    scratch = tempfile.TemporaryDirectory(prefix="gtecat-fuzz-")
    os.chdir(scratch.name)
    for cfg in CONFIGS:
        shutil.copy(EXAMPLES / cfg.name, cfg)
    if not a.verbose:  # the assertion carries the reason; the traceback log is noise here
        logging.getLogger("gtecat").setLevel(logging.CRITICAL)
    restart()
    failed = 0
    warnings: set[str] = set()
    t_all = time.monotonic()
    for name in a.names:
        t0, c0 = time.monotonic(), time.process_time()
        try:
            n = a.twin_examples if name.startswith("GTN_") else a.examples
            fuzz_function(name, n, warnings)
        except Exception as e:
            failed += 1
            text = "".join(traceback.format_exception(e)).strip().splitlines()
            print(f"FAIL {name}:", *text[-25:], sep="\n    ", flush=True)
            try:
                restart()
            except Exception as e2:  # a broken bring-up fails the rest with it
                print(f"FAIL restart after {name}: {e2!r}", flush=True)
                return 1
        else:
            cpu = time.process_time() - c0
            print(f"ok {name} {time.monotonic() - t0:.2f}s (cpu {cpu:.2f}s)", flush=True)
    for w in sorted(warnings):
        print("WARN", w)
    print(f"fuzzed {len(a.names)} functions, {failed} failed, {time.monotonic() - t_all:.1f}s")
    gt.GT_Close()
    os.chdir(EXAMPLES)
    scratch.cleanup()
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
