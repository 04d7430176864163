"""How the GT functions take their pointer and mask arguments (gtecat.gt.args): the element
type of the memory is the pointer's, decided by the type and never by the value; raw data
takes plain memory only; a released memoryview is refused with its reason; ``byref(s,
offset)`` of a structure is the field there; a ``long`` mask takes bit 31 either way.
"""

from __future__ import annotations

import ctypes
import inspect
from ctypes import POINTER, Structure, byref, c_double, c_long, c_short, py_object

import numpy as np
import pytest

from gtecat import gt
from gtecat.errors import ParameterError
from gtecat.gt._core import REGISTRY
from gtecat.gt.args import _element_fits, _pointer_kind, binder, holds_pointers
from gtecat.gt.table import ENUMS, FUNCTIONS, SCALARS, declared_only

from .conftest import bring_up

_NP = [
    np.int8, np.int16, np.int32, np.int64, np.uint8, np.uint16, np.uint32, np.uint64,
    np.float32, np.float64, np.bool_,
]  # fmt: skip
_CT = [
    ctypes.c_byte, ctypes.c_ubyte, ctypes.c_short, ctypes.c_ushort, ctypes.c_int,
    ctypes.c_uint, ctypes.c_long, ctypes.c_ulong, ctypes.c_longlong, ctypes.c_float,
    ctypes.c_double, ctypes.c_bool,
]  # fmt: skip


def _numeric_out_params():
    """(function, parameter index, parameter) of one numeric out pointer per C type."""
    seen, out = set(), []
    for name, proto in sorted(FUNCTIONS.items()):
        if name not in REGISTRY or not name.startswith("GT_"):
            continue
        for i, p in enumerate(proto.params):
            if (
                p.pointer
                and p.direction == "out"
                and p.stars == 1
                and not p.text
                and _pointer_kind(p) == "numbers"
                and (p.ctype in SCALARS or p.ctype in ENUMS)
                and p.ctype not in seen
            ):
                seen.add(p.ctype)
                out.append((name, i, p))
    return out


def _extremes(p):
    if p.ctype in ("double", "float"):
        return [253.265, -1e300, 2.0**-1074]
    _, lo, hi, _ = SCALARS["int" if p.ctype in ENUMS else p.ctype]
    return [lo, hi, 0, 1]


def test_an_accepted_element_type_holds_every_value_of_the_c_type() -> None:
    """Property over every numeric output pointer of the table and every element type (ctypes
    objects, numpy arrays, memoryviews): the binder accepts or refuses by the type alone, and
    memory it accepts takes each extreme value of the C type - back exactly, or as the same
    bit pattern for the same width of the other sign - never truncated, rounded or refused
    for its value (a uint8 buffer for an ``unsigned long *``, an int64 array for a
    ``double *``, a float64 one for a ``long *``: refused whatever the value)."""
    checked = 0
    for name, i, p in _numeric_out_params():
        impl = inspect.unwrap(REGISTRY[name])
        conv = binder(FUNCTIONS[name], impl).convs[i]
        kinds = [("ctypes", t) for t in _CT] + [("numpy", t) for t in _NP]
        kinds += [("memoryview", t) for t in _NP if t is not np.bool_]
        for how, t in kinds:
            for value in _extremes(p):
                if how == "ctypes":
                    mem = (t * 2)()
                    arg, dtype = mem, np.dtype(t._type_ if t is not ctypes.c_long else "l")
                else:
                    mem = np.zeros(2, t)
                    arg = mem if how == "numpy" else memoryview(mem)
                    dtype = mem.dtype
                try:
                    ref = conv(arg)
                except ParameterError as e:
                    assert p.name in str(e) and "pass" in str(e), str(e)
                    accepted = False
                else:
                    ref.store_values([value])
                    accepted = True
                    got = mem[0]
                    if p.ctype in ("double", "float"):
                        assert got == value, (name, how, t, value, got)
                    else:
                        bits = 8 * dtype.itemsize
                        assert int(got) % (1 << bits) == value % (1 << bits), (name, t, value)
                        if dtype.itemsize > (SCALARS["long"][2].bit_length() + 1) // 8:
                            assert int(got) == value  # wider: the value itself
                fits = _element_fits(p, dtype.kind if t is not np.bool_ else "b", dtype.itemsize)
                if t is ctypes.c_bool:
                    fits = False
                assert accepted == fits, (name, p.ctype, how, t, value, accepted)
                checked += 1
    assert checked > 300


@pytest.fixture
def bus():
    bring_up(clock="lockstep")
    gt.GT_ClrSts(1, 2)
    assert gt.GT_AxisOn(1) == 0
    tp = gt.TTrapPrm()
    tp.acc, tp.dec = 0.37, 0.41
    gt.GT_PrfTrap(1)
    gt.GT_SetTrapPrm(1, byref(tp))
    gt.GT_SetPos(1, 123457)
    gt.GT_SetVel(1, 13.7)
    assert gt.GT_Update(1) == 0
    gt.GTE_Wait(37.3)  # a fractional position
    yield


def _refused(rc: int, *words: str) -> None:
    err = gt.GTE_GetLastError()
    assert rc == 7, err
    for w in words:
        assert w in err, err


def test_the_element_type_rule_on_the_bus(bus, capsys) -> None:
    """The checker's cases: a numpy int64 array for GT_GetPrfPos's double * and a float64
    one for GT_GetSts's long * are refused as byref(c_long()) is; a one-byte buffer for
    GT_GetClock's unsigned long * is refused before and after the clock passes 255 ms, and
    GT_GetEcatHomingStatus's unsigned short * likewise; the right types still work."""
    d = c_double()
    assert gt.GT_GetPrfPos(1, byref(d)) == 0 and d.value != int(d.value)
    for bad in (np.zeros(1, np.int64), np.zeros(1, np.int32), np.zeros(1, np.float32)):
        _refused(gt.GT_GetPrfPos(1, bad), "pValue", "double *", "float64")
        assert not bad.any()
    _refused(gt.GT_GetPrfPos(1, memoryview(bytearray(8))), "uint8", "double *")
    good = np.zeros(1, np.float64)
    assert gt.GT_GetPrfPos(1, good) == 0 and good[0] == d.value
    view = memoryview(np.zeros(1)).cast("B").cast("d")
    assert gt.GT_GetPrfPos(1, view) == 0 and view[0] == d.value
    _refused(gt.GT_GetSts(1, np.zeros(1, np.float64)), "pSts", "long *")
    _refused(gt.GT_GetSts(1, bytearray(8)), "bytearray", "long *")
    for ok in (np.zeros(1, np.int32), np.zeros(1, np.int64), np.zeros(1, np.uint32)):
        assert gt.GT_GetSts(1, ok) == 0 and ok[0] != 0
    for wait in (0, 300):  # the clock below and past 255 ms: the same answer
        gt.GTE_Wait(wait)
        for buf in (bytearray(b"\xaa" * 8), bytearray(1)):
            before = bytes(buf)
            _refused(gt.GT_GetClock(memoryview(buf)), "pClock", "uint8")
            assert bytes(buf) == before
        _refused(gt.GT_GetClock(np.zeros(2, np.uint16)), "uint16")
        _refused(gt.GT_GetEcatHomingStatus(1, np.zeros(2, np.uint8)), "uint8")
        _refused(gt.GT_GetEcatHomingStatus(1, memoryview(bytearray(8))), "uint8")
        _refused(gt.GT_GetEcatHomingStatus(1, byref(ctypes.c_ubyte())), "c_ubyte")
        for ok in (np.zeros(1, np.uint32), np.zeros(1, np.int64), ctypes.c_ulong()):
            assert gt.GT_GetClock(ok) == 0, gt.GTE_GetLastError()
        assert gt.GT_GetEcatHomingStatus(1, np.zeros(1, np.uint16)) == 0
        assert gt.GT_GetEcatHomingStatus(1, byref(c_short())) == 0  # either sign, 2 bytes
    assert capsys.readouterr().err == ""


class _S(Structure):
    _fields_ = [("tag", c_short), ("sts", c_long), ("pos", c_double), ("many", c_long * 3)]


class _Outer(Structure):
    _fields_ = [("head", c_short), ("inner", _S)]


def test_byref_of_a_structure_field_writes_that_field_only(bus) -> None:
    """``byref(s, S.field.offset)`` (C's ``&s.field``): the call writes the field, nothing
    else; a field of the other type, or an offset inside a field, is 7 with the reason."""
    want_sts, want_pos = c_long(), c_double()
    assert gt.GT_GetSts(1, byref(want_sts)) == 0 and gt.GT_GetPrfPos(1, byref(want_pos)) == 0
    s = _S(tag=-5, sts=-7, pos=-9.5)
    s.many[:] = [11, 12, 13]
    assert gt.GT_GetSts(1, byref(s, _S.sts.offset)) == 0, gt.GTE_GetLastError()
    assert (s.tag, s.sts, s.pos, list(s.many)) == (-5, want_sts.value, -9.5, [11, 12, 13])
    assert gt.GT_GetPrfPos(1, byref(s, _S.pos.offset)) == 0, gt.GTE_GetLastError()
    assert (s.tag, s.sts, s.pos, list(s.many)) == (-5, want_sts.value, want_pos.value, [11, 12, 13])
    # an array field: its elements from there on
    assert gt.GT_GetSts(1, byref(s, _S.many.offset), 3) == 0, gt.GTE_GetLastError()
    assert s.many[0] == want_sts.value and s.pos == want_pos.value
    _refused(gt.GT_GetSts(1, byref(s, _S.many.offset + ctypes.sizeof(c_long)), 3))
    o = _Outer(head=3)
    off = _Outer.inner.offset + _S.pos.offset
    assert gt.GT_GetPrfPos(1, byref(o, off)) == 0 and o.inner.pos == want_pos.value
    assert o.head == 3 and o.inner.sts == 0
    _refused(gt.GT_GetPrfPos(1, byref(s, _S.sts.offset)), "c_long", "double *")
    _refused(gt.GT_GetSts(1, byref(s, _S.sts.offset + 1)), "not the address of a field")


class _WithPointer(Structure):
    _fields_ = [("p", POINTER(c_long)), ("n", c_long)]


class _WithObject(Structure):
    _fields_ = [("o", py_object)]


def _holders():
    return {
        "py_object": lambda: py_object("hello"),
        "byref(pointer)": lambda: byref(ctypes.pointer(c_long())),
        "struct with POINTER": lambda: _WithPointer(),
        "struct with py_object": lambda: _WithObject(py_object("x")),
        "py_object * 2": lambda: (py_object * 2)("a", "b"),
        "c_char_p * 2": lambda: (ctypes.c_char_p * 2)(b"a", b"b"),
        "POINTER(c_long) * 2": lambda: (POINTER(c_long) * 2)(),
        "c_void_p * 2": lambda: (ctypes.c_void_p * 2)(),
        "byref(py_object * 2)": lambda: byref((py_object * 2)("a", "b")),
    }


def test_raw_data_takes_plain_memory_only(bus) -> None:
    """GT_GetEcatRawData / GT_SetEcatRawData refuse memory holding pointers or Python objects
    (the raw bytes would overwrite an object pointer: a crash later), every time (the fast
    path's shapes included); plain memory still works."""
    o = py_object("hello")
    for _ in range(3):  # (again: a specialised fast entry must refuse it too)
        _refused(gt.GT_GetEcatRawData(0, 2, o), "pValue", "pointers or Python objects")
    assert o.value == "hello"
    for what, make in _holders().items():
        for fn in (gt.GT_GetEcatRawData, gt.GT_SetEcatRawData):
            for _ in range(2):
                rc = fn(0, 2, make())
                assert rc == 7, (what, fn.__name__, gt.GTE_GetLastError())
    assert gt.GT_GetEcatRawData(0, 2, (ctypes.c_ubyte * 2)()) == 0
    assert gt.GT_GetEcatRawData(0, 2, bytearray(2)) == 0
    assert gt.GT_SetEcatRawData(0, 2, bytes(2)) == 0


def test_a_structure_parameter_refuses_a_structure_holding_pointers(bus) -> None:
    """A caller's own structure of the vendor layout is taken (``TTrapPrm`` as a user's
    program declares it), but not one that holds pointers or Python objects where the
    vendor structure has numbers: the doubles written over them left wild pointers (a
    crash at the next look at the object)."""

    class Evil(Structure):
        _fields_ = [(k, py_object) for k in "abcd"]

    class Mine(Structure):
        _fields_ = [(k, c_double) for k in ("acc", "dec", "velStart")] + [("smooth", c_short)]

    e = Evil("w", "x", "y", "z")
    for arg in (byref(e), e, ctypes.pointer(e)):
        _refused(gt.GT_GetTrapPrm(1, arg), "pPrm", "pointers or Python objects")
    assert (e.a, e.d) == ("w", "z")
    mine = Mine()
    assert gt.GT_GetTrapPrm(1, byref(mine)) == 0 and mine.acc > 0


def test_holds_pointers() -> None:
    for t in (py_object, ctypes.c_char_p, ctypes.c_void_p, POINTER(c_long), _WithPointer):
        assert holds_pointers(t) and holds_pointers(t * 2) and holds_pointers((t * 2) * 2)
    for t in (ctypes.c_ubyte, c_long, c_double, _S, _Outer, ctypes.c_char):
        assert not holds_pointers(t) and not holds_pointers(t * 3)


def test_a_released_memoryview_is_7_with_its_reason(bus, capsys) -> None:
    m = memoryview(bytearray(8))
    m.release()
    for call in (
        lambda: gt.GT_GetSts(1, m),
        lambda: gt.GT_GetPrfPos(1, m),
        lambda: gt.GT_GetClock(m),
        lambda: gt.GT_SetEcatRawData(0, 2, m),
        lambda: gt.GT_GetEcatRawData(0, 2, m),
    ):
        for _ in range(2):
            _refused(call(), "released")
    # a live memoryview of the same shape first, then released: the fast entry made for it
    live = bytearray(2)
    v = memoryview(live)
    assert gt.GT_GetEcatRawData(0, 2, v) == 0 and gt.GT_GetEcatRawData(0, 2, v) == 0
    v.release()
    _refused(gt.GT_GetEcatRawData(0, 2, v), "released")
    assert capsys.readouterr().err == ""


def _mask_params():
    emulated = set(REGISTRY) - set(declared_only())
    for name, proto in sorted(FUNCTIONS.items()):
        if name in emulated and name.startswith("GT_"):
            for i, p in enumerate(proto.params):
                if (
                    not p.pointer
                    and "mask" in p.name.lower()
                    and p.ctype in ("long", "unsigned long", "int", "unsigned int")
                ):
                    yield name, proto, i, p


def test_every_32_bit_mask_takes_bit_31_either_way() -> None:
    """Each emulated function's 32-bit mask parameter (found in the table) binds -2^31 and
    2^32-1 (bit 31 as the C ``long`` or as the word) to the word; past that, 7 quoting the
    value as given."""
    found = []
    for name, proto, i, p in _mask_params():
        found.append(name)
        assert p.mask, f"{name} {p.name}: a mask without the table's mask annotation"
        bind = binder(proto, inspect.unwrap(REGISTRY[name]))
        args = [int(q.lo) if q.lo is not None else 1 for q in proto.params]
        for given, word in (
            (-(1 << 31), 0x80000000),
            ((1 << 32) - 1, 0xFFFFFFFF),
            (-1, 0xFFFFFFFF),
        ):
            args[i] = given
            assert bind(tuple(args), {})[0][i] == word, (name, given)
        for given in (1 << 32, -(1 << 31) - 1):
            args[i] = given
            with pytest.raises(ParameterError, match=f"{p.name}={given} "):
                bind(tuple(args), {})
    assert {"GT_Stop", "GT_Update", "GT_MultiAxisOn", "GT_PtStart"} <= set(found)


def test_a_value_that_is_no_pointer_is_named_and_the_accepted_ones_listed(bus) -> None:
    """An ``array.array`` (its 'l' is 8 bytes here, the vendor's long 4), a str, an object:
    7, the value's type named as a user reads it, and what a pointer argument takes."""
    import array

    for value, kind in ((array.array("l", [0]), "an array.array"), ("x", "a str")):
        for _ in range(2):  # (again: the fast path's shapes)
            _refused(gt.GT_GetSts(1, value), "pSts", f"{kind} is not a pointer argument")
        assert "byref(x)" in gt.GTE_GetLastError()
