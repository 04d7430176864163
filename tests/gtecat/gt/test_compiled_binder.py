"""The compiled binder of every emulated function (gtecat.gt.args.fast_binder) gives exactly
what the table's binder gives, or steps aside: it walks the whole table.

For each function a plain call (ints and doubles in range, ``byref(x)`` of a number the
pointer takes, NULL for optional pointers) must be bound by the compiled binder itself (not
left to the table path), and arguments drawn from a pool of odd shapes (out-of-range
numbers, bools, floats for ints, text, NaN, byref with an offset, arrays, numpy, the other
kind of number, missing and extra arguments) must give the table binder's values or None,
never a value the table binder would refuse or convert differently.  No controller runs:
binding is all that is compared.
"""

from __future__ import annotations

import ctypes
import functools
import inspect
import random
from ctypes import byref
from typing import Any

import numpy as np

from gtecat import gt
from gtecat.errors import ParameterError
from gtecat.gt._core import REGISTRY
from gtecat.gt.args import (
    _CTYPES_OF,
    NOT_INLINE,
    Ref,
    _pointer_kind,
    _struct_types,
    binder,
    fast_binder,
)
from gtecat.gt.table import ENUMS, FUNCTIONS, SCALARS, Param

_POINTERS = [
    ctypes.c_long,
    ctypes.c_int,
    ctypes.c_short,
    ctypes.c_ushort,
    ctypes.c_double,
    ctypes.c_float,
    ctypes.c_ulong,
    ctypes.c_ubyte,
]


_STRUCTS = _struct_types()


def _odd(p: Param) -> list[Any]:
    """Shapes of every kind, for any parameter."""
    lo, hi = -(1 << 31), (1 << 31) - 1
    if p.ctype in SCALARS:
        _, lo, hi, _ = SCALARS[p.ctype]
    out: list[Any] = [0, 1, -1, lo, hi, hi + 1, lo - 1, True, 1.0, 2.5, np.int32(3)]
    out += [float("nan"), float("inf"), -1e300, None, "x", b"x"]
    for t in _POINTERS:
        out += [byref(t()), t(), (t * 2)()]
    out += [byref((ctypes.c_long * 3)(), 8), byref(ctypes.c_long(), 4), bytearray(8)]
    out += [np.zeros(2), np.zeros(2, np.int32), [0], ctypes.pointer(ctypes.c_long())]
    out += [ctypes.c_char_p(b"x"), ctypes.create_string_buffer(8)]
    # element types by the rule (the other width or sign, bools), memory holding pointers or
    # Python objects, a released memoryview, a structure's field
    out += [np.zeros(2, d) for d in (np.uint8, np.int16, np.uint32, np.int64, np.bool_)]
    out += [memoryview(bytearray(8)), ctypes.py_object("x"), (ctypes.py_object * 2)()]
    out += [(ctypes.c_void_p * 2)(), byref(ctypes.pointer(ctypes.c_long()))]
    gone = memoryview(bytearray(8))
    gone.release()
    out += [gone, byref(_Field(), _Field.x.offset), byref(_Field(), _Field.d.offset)]
    return out


class _Field(ctypes.Structure):
    _fields_ = [("tag", ctypes.c_short), ("x", ctypes.c_long), ("d", ctypes.c_double)]


def _plain(p: Param) -> Any:
    """A value every table check takes for ``p`` (NotImplemented: none simple)."""
    if p.pointer:
        if p.optional:
            return None
        if p.text or p.is_struct or p.ctype in ("char", "unsigned char", "void") or p.stars != 1:
            return NotImplemented
        return byref(ctypes.c_double() if p.ctype in ("double", "float") else ctypes.c_long())
    if p.is_float:
        return 0.5 if p.lo is None else float(p.lo)
    if p.ctype not in SCALARS and p.ctype not in ENUMS:
        return NotImplemented
    _, lo, hi, _ = SCALARS["int" if p.ctype in ENUMS else p.ctype]
    v = max(lo, 1) if hi >= 1 else lo
    if p.lo is not None:
        v = int(p.lo)
    return v


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, Ref) or isinstance(b, Ref):
        return (
            isinstance(a, Ref)
            and isinstance(b, Ref)
            and (a.name, a.addr, a.nbytes, a.elem) == (b.name, b.addr, b.nbytes, b.elem)
            and a._keep is b._keep
            and _same_py(a.py, b.py)
        )
    return type(a) is type(b) and (a == b or (a != a and b != b))


def _same_py(a: Any, b: Any) -> bool:
    """The Python container behind two Refs: the same object, or two numpy views of the same
    memory (the table binder views a numpy argument afresh each time)."""
    if isinstance(a, np.ndarray) and isinstance(b, np.ndarray):
        return (
            a.__array_interface__ == b.__array_interface__
            and a.dtype == b.dtype
            and np.shares_memory(a, b)
        )
    return a is b


def _bound(bind: Any, args: tuple) -> Any:
    try:
        values, extra = bind(args, {})
    except ParameterError:
        return ParameterError
    assert not extra
    return values


@functools.cache
def _binders() -> list[tuple[str, Any, Any, Any]]:
    out = []
    for name, proto in sorted(FUNCTIONS.items()):
        fn = REGISTRY.get(name)
        if fn is None or not name.startswith(("GT_", "GTE_")):
            continue
        impl = inspect.unwrap(fn)
        bind = binder(proto, impl)
        # (the table's converters asked for when first needed, as the GT functions make it)
        out.append((name, proto, bind, fast_binder(proto, lambda bind=bind: bind.convs)))
    return out


def test_every_function_binds_as_the_table_does() -> None:
    rnd = random.Random(29)
    binders = _binders()
    assert len(binders) > 300
    taken, bad = 0, []
    for name, proto, bind, fast in binders:
        params = proto.params
        plain = tuple(_plain(p) for p in params)
        if NotImplemented not in plain:
            want = _bound(bind, plain)
            got = fast(*plain)
            if want is ParameterError:
                pass  # a range the plain values miss (a parameter tied to another)
            elif got is None:
                bad.append(f"{name}: the plain call {plain!r} left to the table path")
            elif not all(_same(g, w) for g, w in zip(got, want, strict=True)):
                bad.append(f"{name}{plain!r}: compiled {got!r}, table {want!r}")
            else:
                taken += 1
        pools = [[*_odd(p), _plain(p)] for p in params]
        for _ in range(12):
            args = [rnd.choice(pool) for pool in pools]
            args = [a for a in args if a is not NotImplemented]
            cut = rnd.random()
            if cut < 0.15 and args:
                args = args[: rnd.randrange(len(args))]  # arguments left out
            elif cut < 0.2:
                args = [*args, 1]  # one too many
            got = fast(*args)
            if got is None:
                continue
            want = _bound(bind, tuple(args))
            if want is ParameterError or not all(
                _same(g, w) for g, w in zip(got, want, strict=True)
            ):
                bad.append(f"{name}{tuple(args)!r}: compiled {got!r}, table {want!r}")
    assert not bad, "\n".join(bad[:20])
    assert taken > 0.8 * len(binders), f"only {taken} of {len(binders)} plain calls compiled"
    # the converters asked for took their stand-ins' places in the compiled binders
    asked = [
        (bind, fast)
        for _, _, bind, fast in binders
        if any(fast.__globals__[f"C{i}"] is c for i, c in enumerate(bind.convs))
    ]
    assert len(asked) > 0.8 * len(binders)
    for bind, fast in asked:
        assert all(fast.__globals__[f"C{i}"] is c for i, c in enumerate(bind.convs))


def test_the_compiled_binder_serves_the_public_call() -> None:
    """A plain call through gt goes through the compiled binder, and a refused one still
    gets the table's code and reason (the compiled binder never raises)."""
    assert gt.GT_GetClock(byref(ctypes.c_long())) == -1  # not open: the code of the table
    assert "GT_Open" in gt.GTE_GetLastError()
    assert gt.GT_SetVel(1, float("nan")) == 7
    assert "vel" in gt.GTE_GetLastError()
    assert gt.GT_SetVel(1, 2.0, 3) == 7  # one argument too many
    assert gt.GT_GetVel(1, byref(ctypes.c_short())) == 7  # narrower than a double


# --- every shape of every pointer, inline ------------------------------------------------------
def _shapes(p: Param) -> dict[str, Any]:
    """The ways clients pass ``p`` (makers of a fresh argument), by name; a shape the
    compiled binder leaves to the converter on purpose is named as in ``NOT_INLINE``."""
    if p.stars != 1:
        return {"pointer to pointer": None}
    if p.text and p.direction == "in":
        return {"str": lambda: "x"}
    kind = _pointer_kind(p)
    out: dict[str, Any]
    if kind == "numbers":
        t = (
            ctypes.c_double
            if p.ctype in ("double", "float")
            else getattr(ctypes, _CTYPES_OF.get(p.ctype, "c_long"))
        )
        held = byref(t())
        np_type = np.float64 if t is ctypes.c_double else np.int64
        out = {
            "byref": lambda: byref(t()),
            "the same byref": lambda: held,
            "the object": t,
            "ctypes array": lambda: (t * 64)(),
            "byref(array)": lambda: byref((t * 64)()),
            "numpy array": lambda: np.zeros(64, np_type),
        }
    elif kind == "struct":
        cls = _STRUCTS[p.ctype]
        out = {"byref": lambda: byref(cls()), "the object": cls}
    else:
        out = {
            "ctypes array": lambda: (ctypes.c_ubyte * 4096)(),
            "bytearray": lambda: bytearray(4096),
            "numpy array": lambda: np.zeros(4096, np.uint8),
            "string buffer": lambda: ctypes.create_string_buffer(4096),
        }
        if p.direction == "in":
            out["bytes"] = lambda: bytes(4096)
    if p.optional:
        out["NULL as None"] = lambda: None
        out["NULL as 0"] = lambda: 0
    return out


def _spy(conv: Any, i: int, used: list[int]) -> Any:
    """``conv`` noting in ``used`` that parameter ``i`` went through it."""

    def spy(v: Any) -> Any:
        used.append(i)
        return conv(v)

    return spy


def test_every_shape_of_every_pointer_binds_inline_or_has_a_reason() -> None:
    """Each pointer parameter of each emulated function, in each shape a client passes it
    (``byref`` of a fresh or a reused object, the object itself, ctypes and numpy arrays,
    structures, byte buffers, text, NULL as None or 0), the other arguments plain: the
    compiled binder binds it without the table's converter of that parameter, or the table
    refuses the shape too (a single number where the call needs several), or the shape
    has a reason in ``NOT_INLINE``."""
    bad, shapes = [], 0
    for name, proto, bind, _ in _binders():
        params = proto.params
        if not any(p.pointer for p in params):
            continue
        used: list[int] = []
        spies = [_spy(c, i, used) for i, c in enumerate(bind.convs)]
        fast = fast_binder(proto, spies)
        for i, p in enumerate(params):
            if not p.pointer:
                continue
            for shape, make in _shapes(p).items():
                if make is None:
                    if not NOT_INLINE.get(shape, "").strip():
                        bad.append(f"{name} {p.name}: {shape}, no reason")
                    continue
                args = [_plain(q) if j != i else make() for j, q in enumerate(params)]
                for j, q in enumerate(params):  # other pointers: a big array of their kind
                    if j != i and args[j] is NotImplemented:
                        other = _shapes(q)
                        maker = other.get("ctypes array") or other.get("byref") or other.get("str")
                        args[j] = maker() if maker is not None else NotImplemented
                if any(a is NotImplemented for a in args):
                    bad.append(f"{name} {p.name}: {shape}, no plain call to try it in")
                    continue
                shapes += 1
                want = _bound(bind, tuple(args))
                used.clear()
                got = fast(*args)
                if want is ParameterError:
                    if got is not None:
                        bad.append(f"{name} {p.name}: {shape}: the table refuses, compiled binds")
                elif got is None or i in used:
                    bad.append(f"{name} {p.name}: {shape} left to the converter, no reason")
                elif not _same(got[i], want[i]):
                    bad.append(f"{name} {p.name}: {shape}: {got[i]!r} != {want[i]!r}")
    assert not bad, "\n".join(bad[:20])
    assert shapes > 1000
