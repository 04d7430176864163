"""The byref check in C (gtecat/gt/byref_target.py) against its Python reading, and the fast
path's pointer shapes answered as the table answers them with the C check and without it.

The C function says whether a pointer object is ``byref(x)`` of an ``x`` of an accepted type
with no offset (then it gives ``x``, else the pointer itself).  Its reference: ``p._obj``'s
type (or its type's type) in the table and the address ``p`` passes equal to
``addressof(p._obj)``, read from Python.  Then each fast function family (a reader, a PDO
reader, the clock, the raw image) is built once with the C check and once without it, and
every pointer shape a client passes (a fresh or a reused ``byref``, an offset, another type,
a subclass, an object over another's memory) must give the table path's code, value and
reason.
"""

from __future__ import annotations

import ctypes
import sys
from ctypes import byref
from pathlib import Path
from typing import Any

import pytest

from gtecat import gt
from gtecat.gt import _core, byref_target, fast
from gtecat.gt.args import byref_address

ENI = Path(__file__).resolve().parents[3] / "examples" / "manual_fig5_2.eni"
ARRAY_META = type(ctypes.Array)


class _MyLong(ctypes.c_long):
    """A subclass: not one of the accepted types (the table path answers)."""


class _Pair(ctypes.Structure):
    _fields_ = [("a", ctypes.c_long), ("b", ctypes.c_long)]


def _objects() -> list[Any]:
    held = (ctypes.c_long * 4)()
    raw = bytearray(16)
    return [
        ctypes.c_long(3),
        ctypes.c_double(2.5),
        ctypes.c_int(),
        ctypes.c_uint32(),
        ctypes.c_short(),
        _MyLong(),
        held,
        (ctypes.c_ubyte * 8)(),
        _Pair(),
        ctypes.c_long.from_address(ctypes.addressof(held) + 8),
        ctypes.c_long.from_buffer(raw, 8),
        (ctypes.c_ubyte * 4).from_buffer(raw),
    ]


def _pointers() -> list[Any]:
    out = []
    for o in _objects():
        for off in (0, 1, 4, 8, -8, 64):
            out.append(byref(o, off))
    out += [ctypes.c_int.from_param(5), ctypes.c_double.from_param(1.0)]
    # not pointer objects at all: the check gives them back
    out += [ctypes.c_long(), (ctypes.c_long * 2)(), object(), [7], bytearray(b"xy")]
    return out


def _reference(p: Any, table: tuple[type, ...]) -> Any:
    if type(p) is not type(byref(ctypes.c_int())):
        return p
    o = p._obj
    if o is None or not (type(o) in table or type(type(o)) in table):
        return p
    return o if byref_address(p) == ctypes.addressof(o) else p


@pytest.mark.skipif(
    byref_target.target([]) is None, reason=f"the C byref check is not built: {byref_target.REASON}"
)
def test_the_c_check_gives_the_python_reading() -> None:
    tables = [
        (ctypes.c_long,),
        (ctypes.c_double,),
        (ctypes.c_int32, ctypes.c_long, ctypes.c_int64, ctypes.c_longlong),
        (ARRAY_META,),
        (),
    ]
    bad = []
    for table in tables:
        f = byref_target.target(table)
        assert f is not None
        for p in _pointers():
            want = _reference(p, table)
            inner = getattr(p, "_obj", None)
            before = (sys.getrefcount(p), sys.getrefcount(inner))
            got = f(p)
            if got is not want:
                bad.append(f"{table} {p!r} ({type(inner).__name__}): {got!r} != {want!r}")
            del got
            if (sys.getrefcount(p), sys.getrefcount(inner)) != before:
                bad.append(f"{table} {p!r}: reference counts changed")
    assert not bad, "\n".join(bad[:10])


def _open() -> Any:
    assert gt.GT_Open(eni=str(ENI), clock="lockstep", log="") == 0
    assert gt.GT_InitEcatComm() == 0
    gt.GTE_Wait(60)
    assert gt.GT_StartEcatComm() == 0
    assert gt.GT_AxisOn(1) == 0
    gt.GTE_Wait(5)
    return gt.GTE_Controller()


def _built(name: str) -> Any:
    """``name``'s fast function built again around its table path (with fast.BYREF_TARGET
    as it is now)."""
    slow = getattr(gt, name).slow
    if name in fast.READERS:
        return fast.fast_reader(name, slow, _core.SESSION, _core.advance)
    if name in fast.ECAT_READERS:
        return fast.fast_ecat_reader(name, slow, _core.SESSION, _core.advance)
    if name == fast.CLOCK:
        return fast.fast_clock(name, slow, _core.SESSION, _core.advance)
    return fast.fast_raw(name, slow, _core.SESSION, _core.advance)


def _value(o: Any) -> Any:
    return bytes(o) if isinstance(o, ctypes.Array | ctypes.Structure) else o.value


#: (function, arguments before the pointer, arguments after it, how a pointer's object is made)
_FAMILIES = [
    ("GT_GetSts", (1,), (), ctypes.c_long),
    ("GT_GetPrfPos", (1,), (1, 0), ctypes.c_double),
    ("GT_GetEcatEncPos", (1,), (), ctypes.c_long),
    ("GT_GetClock", (), (None,), ctypes.c_long),
    ("GT_GetEcatRawData", (0, 8), (), lambda: (ctypes.c_ubyte * 8)()),
]


@pytest.mark.parametrize("in_c", [True, False], ids=["c check", "python check"])
def test_pointer_shapes_answer_as_the_table(in_c: bool, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(fast, "BYREF_TARGET", in_c)
    _open()
    bad = []
    for name, before, after, make in _FAMILIES:
        fn = _built(name)
        held = make()
        reused = byref(held)
        shapes = {
            "fresh": lambda make=make: (o := make(), byref(o), o),
            "reused": lambda held=held, reused=reused: (held, reused, held),
            "offset": lambda make=make: (o := make(), byref(o, 4), o),
            "other type": lambda: (o := ctypes.c_int16(), byref(o), o),
            "subclass": lambda: (o := _MyLong(), byref(o), o),
            "foreign memory": lambda make=make: (
                h := (ctypes.c_ubyte * 16)(),
                byref(type(make()).from_buffer(h, 8)),
                h,
            ),
        }
        for shape, made in shapes.items():
            got = []
            for call in (fn, fn.slow):
                for _ in range(2):  # (a reused pointer's second call: the checked one)
                    _, p, o = made()
                    if shape == "reused":
                        ctypes.memset(ctypes.addressof(o), 0, ctypes.sizeof(o))
                    rc = call(*before, p, *after)
                got.append((rc, _value(o), gt.GTE_GetLastError() if rc else ""))
            if got[0] != got[1]:
                bad.append(f"{name} {shape}: {got[0]} != {got[1]}")
    assert not bad, "\n".join(bad)


def test_a_structure_packed_at_once_is_the_structure_set_field_by_field() -> None:
    """fast.struct_packer: for every structure of the GT module it can pack, random values
    in each field's range give the bytes that setting the fields one by one gives; a value
    a field would wrap is refused (struct.error: the caller sets the fields then)."""
    import random
    import struct

    from gtecat.gt import structs

    rnd = random.Random(5)
    packed = 0
    for name in dir(structs):
        cls = getattr(structs, name)
        if not (isinstance(cls, type) and issubclass(cls, ctypes.Structure)):
            continue
        pack = fast.struct_packer(cls)
        if pack is None:
            continue
        packed += 1
        for _ in range(50):
            values = []
            for _, t in cls._fields_:
                if t._type_ in "fd":
                    values.append(
                        rnd.choice([0.0, -1.5, 1e300, float("inf"), rnd.uniform(-1e6, 1e6)])
                    )
                else:
                    bits = 8 * ctypes.sizeof(t)
                    lo, hi = (
                        (0, (1 << bits) - 1)
                        if t._type_.isupper()
                        else (-(1 << (bits - 1)), (1 << (bits - 1)) - 1)
                    )
                    values.append(rnd.choice([lo, hi, 0, rnd.randint(lo, hi)]))
            a, b = cls(), cls()
            ctypes.memset(ctypes.addressof(a), 0xA5, ctypes.sizeof(a))
            ctypes.memmove(ctypes.addressof(b), ctypes.addressof(a), ctypes.sizeof(a))
            for (f, _), v in zip(cls._fields_, values, strict=True):
                setattr(a, f, v)
            pack(b, 0, *values)
            assert bytes(a) == bytes(b), (name, values)
        ints = [k for k, (_, t) in enumerate(cls._fields_) if t._type_ not in "fd"]
        if ints:
            values = [0] * len(cls._fields_)
            values[ints[0]] = 1 << 64
            with pytest.raises(struct.error):
                pack(cls(), 0, *values)
    assert packed >= 2  # TTrapPrm and TJogPrm at least
