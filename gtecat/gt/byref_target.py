"""One C call that tells whether a ``byref`` is ``byref(x)`` of an accepted ``x``.

The fast path (:mod:`gtecat.gt.fast`) answers ``GT_GetSts(1, byref(c_long()))`` only when the
pointer passes the address of its object's own memory (``byref(x)``, not ``byref(x, offset)``,
which the table path answers).  ctypes keeps that address inside the pointer object and offers
no reader for it; read from Python it costs an ``id``, a shift, an index into process memory
and an ``addressof`` (about as much as making the ``byref(c_long())`` itself).  Here the whole
question is one call of a C function (``csrc/byref_target.c``, built like the bank's kernel:
``cc`` on first use, into the per-version cache): :func:`target` gives, for a set of accepted
types, ``f(p)`` -> ``x`` for such a pointer, else ``p`` itself.

The C file uses no Python header: where the interpreter keeps the pointer's address and its
object, an object's type and a ctypes object's memory is found here by probing objects whose
answers are known, handed to the library, and the function is then tested against those
answers (offsets, other types, arrays, objects over foreign memory, reference counts).  Any
disagreement, or no compiler: :data:`REASON` says why, :func:`target` gives None, and the fast
path reads the address from Python as before (same answers, slower).
"""

from __future__ import annotations

import ctypes
import logging
import sys
from collections.abc import Callable, Iterable
from typing import Any

from ..cparts import GT_CFLAGS
from .args import CARG_AT

log = logging.getLogger(__name__)

#: flags of the build, also the C entry's (gtecat.gt.centry): why -O1, gtecat.cparts says
CFLAGS = GT_CFLAGS
_METH_O = 0x0008
_WORD = ctypes.sizeof(ctypes.c_void_p)


class _MethodDef(ctypes.Structure):
    """CPython's ``PyMethodDef`` (stable ABI)."""

    _fields_ = [
        ("ml_name", ctypes.c_char_p),
        ("ml_meth", ctypes.c_void_p),
        ("ml_flags", ctypes.c_int),
        ("ml_doc", ctypes.c_char_p),
    ]


def _word(address: int) -> int:
    return ctypes.c_void_p.from_address(address).value or 0


def layout() -> tuple[int, int, int, int]:
    """(pointer's address, pointer's object, object's type, ctypes object's memory): byte
    offsets, each checked on objects whose answers are known (ValueError when one is not)."""
    if sys.implementation.name != "cpython" or CARG_AT is None:
        raise ValueError("not CPython, or where a byref keeps its address is not known")
    head = object.__basicsize__  # (PyObject_HEAD: the type is its last word)
    ob_type, b_ptr = head - _WORD, head
    objs = [
        ctypes.c_long(7),
        ctypes.c_double(),
        (ctypes.c_int * 3)(),
        ctypes.c_int.from_buffer(bytearray(8)),
        (ctypes.c_ubyte * 16)(),
    ]
    for o in [*objs, 1.5, "text", object()]:
        if _word(id(o) + ob_type) != id(type(o)):
            raise ValueError("an object's type is not where it is looked for")
    for o in objs:
        if _word(id(o) + b_ptr) != ctypes.addressof(o):
            raise ValueError("a ctypes object's memory is not where it is looked for")
    size = sys.getsizeof(ctypes.byref(ctypes.c_int()))
    for k in range(head, size - _WORD + 1, _WORD):
        if k != CARG_AT and all(
            _word(id(p) + k) == id(o) for o in objs for p in (ctypes.byref(o), ctypes.byref(o, 4))
        ):
            return CARG_AT, k, ob_type, b_ptr
    raise ValueError("where a byref keeps its object is not known")


_KEEP: list[Any] = []  # the method definitions and tables the functions point at


def function_maker() -> Callable[..., Any]:
    """``new(name, address, flags, self, keep)``: the C function at ``address`` (a
    ``PyCFunction`` of calling convention ``flags``) bound to ``self`` (a ctypes object,
    whose memory the function reads) as a Python built-in function; its method definition,
    ``self`` and ``keep`` are kept alive for as long as the process runs."""
    # (a prototype of our own: ctypes.pythonapi's function objects are shared)
    proto = ctypes.PYFUNCTYPE(ctypes.py_object, ctypes.c_void_p, ctypes.py_object, ctypes.py_object)
    bind = proto(("PyCFunction_NewEx", ctypes.pythonapi))

    def new(name: bytes, address: int, flags: int, self: Any, keep: Any) -> Any:
        md = _MethodDef(name, address, flags, None)
        _KEEP.append((md, self, keep))
        return bind(ctypes.addressof(md), self, None)

    return new


def _load() -> tuple[Callable[[Iterable[type]], Callable[[Any], Any]] | None, str]:
    """The maker of target functions, or None and why not."""
    try:
        layout_ = layout()
    except ValueError as e:
        return None, str(e)
    try:
        from ..cbuild import c_source, shared_library

        source = c_source("gtecat.gt", "byref_target")
        lib = ctypes.CDLL(str(shared_library("byref_target", source, CFLAGS, ())))
        lib.gtecat_byref_layout.argtypes = [ctypes.c_ssize_t] * 4 + [ctypes.c_void_p] * 2
        lib.gtecat_byref_layout.restype = ctypes.c_int
        incref = ctypes.cast(ctypes.pythonapi.Py_IncRef, ctypes.c_void_p).value
        carg = id(type(ctypes.byref(ctypes.c_int())))
        if lib.gtecat_byref_layout(*layout_, incref, carg) != 0:
            return None, "the library refused the layout"
        meth = ctypes.cast(lib.gtecat_byref_target, ctypes.c_void_p).value
        new = function_maker()
    except Exception as e:  # no compiler, a failed build, no Python API in this process
        return None, f"{type(e).__name__}: {e}"

    def make(types: Iterable[type]) -> Callable[[Any], Any]:
        kinds = tuple(types)
        table = (ctypes.c_void_p * (len(kinds) + 1))(*(id(t) for t in kinds), 0)
        return new(b"byref_target", meth, _METH_O, table, (kinds,))

    reason = _self_test(make)
    return (make, "") if not reason else (None, reason)


def _self_test(make: Callable[[Iterable[type]], Callable[[Any], Any]]) -> str:
    """'' when a target function gives the known answers and keeps reference counts, else
    what it got wrong."""
    long_arr = ctypes.c_long * 4
    f = make([ctypes.c_long, ctypes.c_double, type(long_arr)])
    held = long_arr()
    cases: list[tuple[Any, Any]] = []
    for o in (
        ctypes.c_long(5),
        ctypes.c_double(),
        held,
        ctypes.c_long.from_address(ctypes.addressof(held)),
    ):
        cases.append((ctypes.byref(o), o))  # its own memory: the object
        cases.append((ctypes.byref(o, 8), None))  # an offset: the pointer itself
        cases.append((ctypes.byref(o, -8), None))
    for o in (ctypes.c_int(), ctypes.c_short(), ctypes.c_ulong(), (ctypes.c_ubyte * 8)()):
        cases.append((ctypes.byref(o), o if type(type(o)) is type(long_arr) else None))
    cases.append((ctypes.c_int.from_param(5), None))  # a pointer object with no ctypes object
    for x in (held, ctypes.c_long(), object(), [5]):  # not pointer objects: themselves
        cases.append((x, None))
    for p, want in cases:
        inner = getattr(p, "_obj", None)
        before = (sys.getrefcount(p), sys.getrefcount(inner))
        for _ in range(3):
            got = f(p)
            if got is not (p if want is None else want):
                return f"the byref check answered {got!r} for {p!r}"
            del got
        if (sys.getrefcount(p), sys.getrefcount(inner)) != before:
            return "the byref check changed a reference count"
    return ""


_MAKE, REASON = _load()
if _MAKE is None:
    log.debug("byref check in C not used: %s", REASON)


def target(types: Iterable[type]) -> Callable[[Any], Any] | None:
    """``f(p)``: for a ``byref`` object ``p``, ``p``'s object when its type (or its type's
    type: ``type(ctypes.Array)``'s for any array) is one of ``types`` and ``p`` passes the
    address of that object's own memory; else (any other argument too) ``p``.  None where
    the C function is not available (:data:`REASON`)."""
    return None if _MAKE is None else _MAKE(types)
