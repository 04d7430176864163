"""A pointer into an array (``byref(arr, offset)``, C's ``&arr[k]``) on the fast path.

Generated arrays (element types the readers take and others, lengths 1..12), byte offsets
(whole elements, between two, before the start, at and past the end) and counts (a span
that fits behind the pointer, one that runs past the object's end), and for the raw image
functions buffers, byte offsets and sizes: the public function (its C entry in front), its
Python fast function and its table path each answer the same call - return code, every
byte of the array (and of the image), the clock written, GTE_GetLastError.
"""

from __future__ import annotations

import ctypes
from ctypes import byref

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gtecat import gt
from gtecat.gt import fast
from tests.conftest import examples

from .test_fast import moving_bus  # noqa: F401  (the fixture: 3 axes moving, lockstep)

D, L, S, UL = ctypes.c_double, ctypes.c_long, ctypes.c_short, ctypes.c_ulong
#: functions of every kind of reader the fast path has: (name, arguments before the pointer,
#: the element type a client's array has)
FUNCTIONS = [
    ("GT_GetPrfPos", (1,), D),
    ("GT_GetEncVel", (2,), D),
    ("GT_GetSts", (1,), L),
    ("GT_GetPrfMode", (5,), L),
    ("GT_GetEcatEncPos", (1,), L),
    ("GT_GetEcatAxisDI", (2,), UL),
    ("GT_GetDi", (gt.MC_GPI,), L),
    ("GT_GetDo", (gt.MC_GPO,), L),
    ("GT_GetEcatHomingStatus", (1,), S),
    ("GT_GetClock", (), UL),
    ("GT_GetCore", (), S),
    ("GT_IsEcatReady", (), S),
]
TYPES = [
    ctypes.c_double,
    ctypes.c_long,
    ctypes.c_int32,
    ctypes.c_uint32,
    ctypes.c_short,
    ctypes.c_ushort,
    ctypes.c_ulong,
    ctypes.c_int8,
    ctypes.c_float,
]


def _settings(long: int, default: int) -> settings:
    """A property test's settings here: derandomized, no deadline, the bus fixture kept."""
    return settings(
        max_examples=examples(long, default),
        deadline=None,
        derandomize=True,
        suppress_health_check=[HealthCheck.function_scoped_fixture],
    )


def _paths(name: str) -> list:
    """The public function, its Python fast function (where it has a C entry in front),
    its table path."""
    fn = getattr(gt, name)
    python = getattr(fn, "python", None)
    return [f for f in (fn, python, fn.slow) if f is not None]


@_settings(200, 25)
@given(
    fn=st.sampled_from(FUNCTIONS),
    t=st.one_of(st.none(), st.none(), st.sampled_from(TYPES)),  # (None: the client's type)
    length=st.integers(1, 12),
    k=st.one_of(st.integers(0, 3), st.integers(-1, 13)),
    between=st.sampled_from([0, 0, 0, 1, 3]),
    count=st.sampled_from([None, 1, 2, 3, 4, 8, 13]),
    clock=st.booleans(),
)
def test_byref_into_an_array_answers_as_the_table(
    moving_bus,  # noqa: F811
    fn,
    t,
    length,
    k,
    between,
    count,
    clock,
) -> None:
    name, before, usual = fn
    t = usual if t is None else t
    offset = k * ctypes.sizeof(t) + between
    span = name in fast.READERS
    results = []
    for f in _paths(name):
        arr = (t * length)(*([7] * length))
        try:
            p = byref(arr, offset)
        except (ValueError, TypeError):  # (an offset ctypes refuses itself)
            pytest.skip("ctypes refuses the offset")
        args = [*before, p]
        clk = ctypes.c_uint32(5)
        if span and (count is not None or clock):
            args.append(1 if count is None else count)
            if clock:
                args.append(byref(clk))
        rc = f(*args)
        results.append((rc, bytes(arr), clk.value, gt.GTE_GetLastError() if rc else ""))
    assert all(r == results[-1] for r in results), (name, t, length, offset, count, results)


def test_the_span_lands_at_the_offset(moving_bus) -> None:  # noqa: F811
    """``GT_GetPrfPos(1, byref(d, 8*k), n)``: the n axes' positions in d[k..k+n-1], d[k+n..]
    untouched; past the end: the table path's refusal, the array untouched."""
    want = (ctypes.c_double * 3)()
    assert gt.GT_GetPrfPos(1, want, 3, None) == 0
    d = (ctypes.c_double * 6)(*[-1.0] * 6)
    assert gt.GT_GetPrfPos(1, byref(d, 16), 3, None) == 0
    assert list(d) == [-1.0, -1.0, *want, -1.0]
    assert gt.GT_GetPrfPos(1, byref(d, 32), 3, None) == 7
    assert "room for 2 value(s)" in gt.GTE_GetLastError()
    assert list(d) == [-1.0, -1.0, *want, -1.0]


#: the raw image functions: (name, arguments before offset and size, a write into the image)
RAW = [
    ("GT_GetEcatRawData", (), False),
    ("GT_SetEcatRawData", (), True),
    ("GT_EcatIOReadInput", (2,), False),
    ("GT_EcatIOWriteOutput", (2,), True),
]


@_settings(200, 25)
@given(
    fn=st.sampled_from(RAW),
    t=st.sampled_from([ctypes.c_ubyte, ctypes.c_ubyte, ctypes.c_char, ctypes.c_uint16]),
    length=st.integers(1, 12),
    at=st.one_of(st.integers(0, 3), st.integers(-1, 13)),
    where=st.sampled_from([0, 2, 4, 8, 32, 36, 60]),
    size=st.integers(1, 6),
)
def test_byref_into_a_raw_buffer_answers_as_the_table(
    moving_bus,  # noqa: F811
    fn,
    t,
    length,
    at,
    where,
    size,
) -> None:
    """The raw image functions with ``byref(buf, k)`` (C's ``&buf[k]``, any byte offset):
    the same code, buffer and image as the table path, a range past the buffer's end
    refused the same way."""
    name, before, write = fn
    if name in ("GT_EcatIOWriteOutput", "GT_EcatIOReadInput"):
        where %= 4
    elif write:
        where = 32 + where % 6  # (the IO slaves' outputs: what a raw write may touch)
    results = []
    for f in _paths(name):
        buf = (t * length)()
        ctypes.memmove(buf, bytes(range(1, ctypes.sizeof(buf) + 1)), ctypes.sizeof(buf))
        try:
            p = byref(buf, at)
        except (ValueError, TypeError):
            pytest.skip("ctypes refuses the offset")
        rc = f(*before, where, size, p)
        image = (ctypes.c_ubyte * 64)()
        assert gt.GT_GetEcatRawData.slow(0, 64, image) in (0, 7)
        results.append((rc, bytes(buf), bytes(image), gt.GTE_GetLastError() if rc else ""))
        if write and rc == 0:  # (the next path writes over other bytes: each its own)
            zero = (ctypes.c_ubyte * size)()
            assert getattr(gt, name).slow(*before, where, size, zero) == 0
    assert all(r == results[-1] for r in results), (name, t, length, at, where, size, results)


@_settings(100, 15)
@given(
    length=st.integers(1, 4),
    k=st.integers(-1, 5),
    between=st.sampled_from([0, 0, 8, 26]),
    axis=st.sampled_from([1, 1, 3]),
)
def test_byref_into_an_array_of_structures_answers_as_the_table(
    moving_bus,  # noqa: F811
    length,
    k,
    between,
    axis,
) -> None:
    """``GT_GetTrapPrm(axis, byref(prm, k * sizeof(TTrapPrm)))`` (C's ``&prm[k]``) and the
    array itself: the structure there as the table path writes it, or its refusal."""
    offset = k * ctypes.sizeof(gt.TTrapPrm) + between
    results = []
    for f in _paths("GT_GetTrapPrm"):
        arr = (gt.TTrapPrm * length)()
        ctypes.memset(arr, 0x5A, ctypes.sizeof(arr))  # (padding and fields: all compared)
        try:
            p = arr if k == -1 and between == 0 else byref(arr, offset)
        except (ValueError, TypeError):
            pytest.skip("ctypes refuses the offset")
        rc = f(axis, p)
        results.append((rc, bytes(arr), gt.GTE_GetLastError() if rc else ""))
    assert all(r == results[-1] for r in results), (length, offset, axis, results)
