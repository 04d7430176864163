"""The GT fast path: the common getters in a handful of Python calls.

A polling loop (``do { GT_GetSts(axis, &sts); } while (sts & 0x400);``) spends most of
its wall time in the GT layer: the table binder (:mod:`gtecat.gt.args`) checks and
resolves every argument generically.  For the readers below the one shape nearly every
caller uses - ``(int axis, byref(c_long()) or a ctypes array)`` with ``count`` 1 and no
``pClock``, on the in-process controller - is recognised up front and answered from the
axis resources directly (or from the axis bank, :mod:`gtecat.controller.bank`); every other
shape, and anything the fast test is unsure of, takes the table path unchanged, so the
return codes and reasons stay the table's.  The fast answer is the table path's answer:
``tests/gtecat/gt/test_fast.py`` compares both over generated arguments.
"""

from __future__ import annotations

import ctypes
import os
import re
import struct
import sys
import time
from array import array
from collections.abc import Callable
from operator import itemgetter
from typing import Any

import numpy as np

from .._code_store import compiled as _compiled_code
from ..controller.axis_status import AxisStatus
from ..controller.bank import BANK_READS
from ..controller.core_view import AXES_PER_CORE
from ..controller.epoch import EPOCH, changed
from ..controller.motion.trap import IDLE_MODE as TRAP_IDLE
from ..controller.motion.trap import TrapPlanner
from ..controller.resources import CONTROLLER_AXES, AxisResources, resource_count
from ..master.clock import ClockMode
from . import byref_target, centry
from .args import CARG_AT, CARG_ENV, byref_address, carg_address_source, holds_pointers
from .fast_legacy_home import HOME_STS, fast_home_sts

_CArg = type(ctypes.byref(ctypes.c_int()))
_NDARRAY = np.ndarray


_NO: Any = object()  # an argument the caller did not pass
_addressof = ctypes.addressof
_from_address = ctypes.c_void_p.from_address
#: where a byref() keeps its address (args.CARG_AT); -1: not known (byref_address reads it)
_AT = CARG_AT if CARG_AT is not None else -1


_ARRAY_META = type(ctypes.Array)


def array_at(p: Any) -> Any:
    """The elements ``byref(array[, offset])`` points at (C's ``&array[k]``): the array itself
    for no offset, else a ctypes array of its element type over its memory from the
    pointer's address to the object's end (keeping the array alive), which a fast path
    writes as it writes an array (its length is the table path's room behind the pointer);
    None where ``p`` is not a byref of a ctypes array or its address is not at a whole
    element inside it (the table path answers, or refuses: an offset outside the object)."""
    if type(p) is not _CArg:
        return None
    arr = p._obj
    tp = type(arr)
    if type(tp) is not _ARRAY_META:
        return None
    off = (_from_address(id(p) + _AT).value if _AT >= 0 else byref_address(p)) - _addressof(arr)
    if off == 0:
        return arr
    elem = tp._type_
    size = ctypes.sizeof(elem)
    total = ctypes.sizeof(arr)
    if off < 0 or off % size or off >= total:
        return None
    try:
        return (elem * ((total - off) // size)).from_buffer(arr, off)
    except (TypeError, ValueError):  # (memory ctypes does not export writable: the table)
        return None


def element_at(p: Any, ok: Any) -> Any:
    """The element ``byref(array[, offset])`` points at (C's ``&array[k]``), as a ctypes
    object of the array's element type over that memory, where that type is one of ``ok``
    and the address is at a whole element inside the array; else None (the table path)."""
    arr = p._obj
    tp = type(arr)
    if type(tp) is not _ARRAY_META or tp._type_ not in ok:
        return None
    elem = tp._type_
    off = (_from_address(id(p) + _AT).value if _AT >= 0 else byref_address(p)) - _addressof(arr)
    size = ctypes.sizeof(elem)
    if off < 0 or off % size or off + size > ctypes.sizeof(arr):
        return None
    try:
        return elem.from_buffer(arr, off)
    except (TypeError, ValueError):  # (memory ctypes does not export writable: the table)
        return None


#: a ctypes array type -> its memoryview's format (view_array)
_VIEWS: dict[type, str] = {}
#: the last view found whole and its array (a polling loop passes the same view)
_LAST_VIEW: list[Any] = [None, None]


def view_array(v: memoryview) -> Any:
    """The ctypes array ``v`` is a whole, writable view of (``memoryview(arr)``: the array's
    own format, all its bytes), else None: a reader writes its value into that array's first
    element as into the array itself, as the table path writes it through the view (its
    numpy array of the same memory and element type)."""
    try:
        o = v.obj
        if v is _LAST_VIEW[0]:  # (a view's object, format and size never change)
            return _LAST_VIEW[1]
        tp = type(o)
        if type(tp) is not _ARRAY_META or v.readonly:
            return None
        own = _VIEWS.get(tp)
        if own is None:
            with memoryview(o) as m:
                own = _VIEWS[tp] = m.format
        if v.format != own or v.nbytes != ctypes.sizeof(o):
            return None
    except ValueError:  # (a released view: the table path says why)
        return None
    _LAST_VIEW[:] = v, o  # (held: its id is not another's while it is here)
    return o


_status = AxisResources.status
#: a C ``short`` argument's range (the table binder's check of ``axis`` and ``count``)
_SHORT_MIN, _SHORT_MAX = -(1 << 15), (1 << 15) - 1


def pointee(p: Any) -> Any:
    """``x`` for ``pointer(x)`` (or a pointer whose ``contents`` was set to ``x``) still
    pointing at ``x``'s own memory, else None: a NULL pointer, or a cast of other memory (an
    address, a smaller object, numpy's ``data_as``), whose size behind it nothing proves
    (the table path refuses it with 7).  ctypes keeps that ``x`` in the pointer's own
    ``_objects`` under ``'1'`` (its contents setter); the C entry checks the same."""
    kept = p._objects
    x = kept.get("1") if type(kept) is dict else None
    if (
        x is None
        or type(x) is not type(p)._type_  # (a cast of pointer(y) to another type keeps y)
        or not p
        or ctypes.addressof(x) != ctypes.cast(p, ctypes.c_void_p).value
    ):
        return None
    return x


def _kept_refs() -> int:
    """References a pointer object has inside a fast reader when nothing else holds it (a
    ``byref(c_long())`` made in the call): a checked ``byref`` is kept for the next call only
    when the caller holds it too (a reused pointer), else keeping it alive would stop the next
    fresh one from taking its memory, which costs more than the check it saves."""

    def probe(p: Any) -> int:
        return sys.getrefcount(p)

    return probe(ctypes.byref(ctypes.c_long()))


#: see :func:`_kept_refs`
_KEPT = _kept_refs()
#: fast paths' caches of one controller's objects (its axes, their states), emptied whenever
#: the gates change (a controller closed, another one selected): a closed controller is not
#: kept alive by them
_CACHES: list[dict[Any, Any]] = []
_LOCKSTEP = ClockMode.LOCKSTEP


def attr_getter(name: str) -> Callable[[Any], float]:
    """One axis's reading ``name`` as a double (the table readers of motion_calls use it too)."""

    def get(r: Any) -> float:
        return float(getattr(r, name))

    get.attr = name  # type: ignore[attr-defined]  # (the fast reader reads it inline)
    return get


def prf_mode_value(r: Any) -> int:
    """GT_GetPrfMode's value (motion_calls)."""
    return int(r.profile.mode)


#: table 6-2 bit 10: the one bit of a profile's own (GT_GetPrfSts)
_PRF_MOVING = int(AxisStatus.MOVING)


def prf_sts_value(r: Any) -> int:
    """GT_GetPrfSts's word (status_calls): the planner's bit of GT_GetSts's."""
    return r.status() & _PRF_MOVING


_INTS = frozenset({ctypes.c_int32, ctypes.c_long, ctypes.c_int64, ctypes.c_longlong})
_DOUBLE = frozenset({ctypes.c_double})
#: numpy arrays the fast path writes element 0 of (the table path's flat[:1] = [value])
_NP_INTS = frozenset({np.dtype(np.int32), np.dtype(np.int64)})
_NP_DOUBLE = frozenset({np.dtype(np.float64)})

#: function -> (value of one axis's resources, the ctypes types *pValue may have: ``long`` is
#: the vendor's 32 bits, and a Python caller's ``c_long()`` is 64 bits on Linux; both work)
READERS: dict[str, tuple[Callable[[Any], Any], frozenset]] = {
    "GT_GetSts": (_status, _INTS),
    "GT_GetPrfPos": (attr_getter("prf_pos"), _DOUBLE),
    "GT_GetPrfVel": (attr_getter("prf_vel"), _DOUBLE),
    "GT_GetPrfAcc": (attr_getter("prf_acc"), _DOUBLE),
    "GT_GetAxisPrfPos": (attr_getter("axis_prf_pos"), _DOUBLE),
    "GT_GetAxisPrfVel": (attr_getter("axis_prf_vel"), _DOUBLE),
    "GT_GetAxisEncPos": (attr_getter("axis_enc_pos"), _DOUBLE),
    "GT_GetAxisEncVel": (attr_getter("axis_enc_vel"), _DOUBLE),
    "GT_GetAxisError": (attr_getter("axis_error"), _DOUBLE),
    "GT_GetEncPos": (attr_getter("enc_pos"), _DOUBLE),
    "GT_GetEncVel": (attr_getter("enc_vel"), _DOUBLE),
    "GT_GetAxisPrfAcc": (attr_getter("axis_prf_acc"), _DOUBLE),
    "GT_GetAxisEncAcc": (attr_getter("axis_enc_acc"), _DOUBLE),
    "GT_GetPrfMode": (prf_mode_value, _INTS),
    "GT_GetPrfSts": (prf_sts_value, _INTS),
}


def fast_reader(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """``slow`` (the table-checked GT function) with the fast path in front of it;
    ``advance(ctl, name, rc)`` runs the call's host latency, catching what the cycle raises."""
    from .table import FUNCTIONS

    get, ctypes_ok = READERS[name]
    np_ok = _NP_INTS if ctypes_ok is _INTS else _NP_DOUBLE
    last: list[Any] = [None]  # the last byref object checked (kept alive, so never reused)
    array_types: dict[type, bool] = {}

    def is_array(tp: type) -> bool:
        ok = array_types.get(tp)
        if ok is None:
            ok = array_types[tp] = (
                issubclass(tp, ctypes.Array) and tp._type_ in ctypes_ok and tp._length_ >= 1
            )
        return ok

    pointer_types: dict[type, bool] = {}

    def is_pointer(tp: type) -> bool:
        """``pointer(x)`` (a ctypes pointer object) of a type ``*pValue`` takes."""
        ok = pointer_types.get(tp)
        if ok is None:
            ok = pointer_types[tp] = (
                issubclass(tp, ctypes._Pointer) and getattr(tp, "_type_", None) in ctypes_ok
            )
        return ok

    env = {
        "_NO": _NO,
        "_CArg": _CArg,
        "_LOCKSTEP": _LOCKSTEP,
        "_addressof": _addressof,
        "_from_address": _from_address,
        "byref_address": byref_address,
        "session": session,
        "get": get,
        "ok": ctypes_ok,
        "last": last,
        "LAST_P": None,
        "_refs": sys.getrefcount,
        "KEPT": _KEPT,
        "advance": advance,
        "name": name,
        "slow": slow,
        "key": BANK_LISTS.get(name),
        "_NDARRAY": _NDARRAY,
        "np_ok": np_ok,
        "is_array": is_array,
        "view_array": view_array,
        "to": float if ctypes_ok is _DOUBLE else None,
        "T0": ctypes.c_double if ctypes_ok is _DOUBLE else ctypes.c_long,  # the usual type
    }
    gt = _compiled(_READER, "gt", env, core="", session="session.plain")

    def general(n: Any, p: Any, count: Any, pClock: Any, extra: tuple, kw: dict) -> int:
        """Every other shape: count 1, pClock NULL (0 or None, the manual's own form), an
        array, a numpy array, and anything the table path must answer."""
        ctl = session.controllers.get(1)
        # byref(array[, offset]) (C's &array[k]): its elements from there, as an array's
        q = p if type(p) is not _CArg else (array_at(p) or p)
        if type(count) is int and count > 1:
            rc = many(ctl, n, q, count, pClock, extra, kw)
            if rc is not None:
                return rc
            return slow(*(a for a in (n, p, count, pClock) if a is not _NO), *extra, **kw)
        if (
            type(n) is not int
            or extra
            or kw
            or ctl is None
            or (count is not _NO and (type(count) is not int or count != 1))
            or session.remote is not None
            or session.core != 1  # GT_SetCore: another core
        ):
            return slow(*(a for a in (n, p, count, pClock) if a is not _NO), *extra, **kw)
        clk = clock_out(ctl, pClock)
        if clk is False:
            return slow(*(a for a in (n, p, count, pClock) if a is not _NO))
        res = ctl.resources.get(n)
        clock = ctl.clock
        if res is None or clock._thread is not None:
            return slow(*(a for a in (n, p, count, pClock) if a is not _NO))
        tp = type(q)
        if tp is _CArg:
            obj = p._obj
            if p is not last[0]:
                # byref(obj), not byref(obj, offset): the address it holds is the object's
                if type(obj) not in ctypes_ok or (
                    _from_address(id(p) + _AT).value if _AT >= 0 else byref_address(p)
                ) != _addressof(obj):
                    return slow(*(a for a in (n, p, count, pClock) if a is not _NO))
                last[0] = p  # checked: the same pointer object next time needs no check
            obj.value = get(res)
        elif tp in ctypes_ok:  # the ctypes object itself (ctypes passes it by reference)
            p.value = get(res)
        elif is_array(tp):
            q[0] = get(res)
        elif (
            tp is _NDARRAY
            and p.dtype in np_ok
            and p.ndim == 1
            and p.size
            and p.flags.writeable
            and p.flags.c_contiguous  # (a strided view: the table path's 7)
        ):
            p[0] = get(res)
        elif is_pointer(tp) and (x := pointee(p)) is not None:  # pointer(x): x
            x.value = get(res)
        else:
            return slow(*(a for a in (n, p, count, pClock) if a is not _NO))
        if clk is not None:
            clk[0].value = clk[1]
        session.last = None
        if clock.mode is not _LOCKSTEP:
            return advance(ctl, name, 0)
        return 0

    clock_target = _target(_CLOCK_INTS)
    takes_clock = [q.name for q in FUNCTIONS[name].params[3:4]] == ["pClock"]

    def clock_out(ctl: Any, pClock: Any) -> Any:
        """What a reader's ``pClock`` gets, as its table path stores it (the controller's
        milliseconds since GT_Reset, 32 bits): None for NULL (omitted, None or 0, the
        manual's own form), ``(object, value)`` for ``byref(x)`` or ``x`` of an integer type
        that holds the value, False for anything else (the table path answers)."""
        if pClock is _NO or pClock is None or (type(pClock) is int and pClock == 0):
            return None
        if not takes_clock:
            return False
        obj = clock_scalar(clock_target, pClock)
        if obj is None:
            return False
        tp = type(obj)
        ms = ctl.clock_ms() & 0xFFFFFFFF
        if ms > _INT_MAX[tp]:
            return False
        return obj, ms

    own_limit = READ_LIMITS.get(name)  # the function's own (its table path refuses more)
    # (no limit of its own: a span of any length inside the controller's axes, which span()
    # proves; a count no C short holds: the table path)
    limit = _SHORT_MAX if own_limit is None else own_limit
    bank_key = BANK_LISTS.get(name)
    #: a reader whose value a row of the bank gives through a link or a bit (DERIVED): a
    #: span's plan writes each row's value as BANK_ROWS' expression (that row alone, not
    #: every row's list); its plans are kept under the reader's name
    row_expr = BANK_ROWS.get(name) if bank_key is None else SPAN_ROWS.get(name)
    plan_key = bank_key if row_expr is None else name
    quick = QUICK_ROWS.get(name)  # (its rows' values in fewer steps where it may)
    source = QUICK_SOURCES.get(name)  # (and where those values come from: the C entry's)
    #: a span's values are status words alone (of the bank's rows, their flags): they stand
    #: while every change is a cycle that keeps every flag (the C entry's array_value)
    status = name in ("GT_GetSts", "GT_GetPrfSts")

    core: list[Any] = []  # (CMD_PARAM, _record): the GT layer imports this module first

    def refuse(ctl: Any, reason: str) -> int:
        """The table path's refusal of a parameter (code 7 and the reason), then the call's
        host latency."""
        if not core:
            from ._core import CMD_PARAM, _record

            core[:] = (CMD_PARAM, _record)
        code, record = core
        record(name, code, reason)
        return advance(ctl, name, code)

    def many(
        ctl: Any,
        n: Any,
        p: Any,
        count: int,
        pClock: Any,
        extra: tuple,
        kw: dict,
        zeros: bool = True,
    ) -> Any:
        """``count`` axes from ``n`` into a ctypes array or a numpy array of the reader's
        dtypes (``GT_GetSts(1, sts, 12, NULL)``, a poll of every axis in one call): the table
        path's values, or None when the shape is any other (a strided, read-only or short
        numpy array, a span past the controller's axes: the table).  An axis
        of the controller's that no drive backs reads 0 where ``zeros`` (core 1's own axes;
        a core view counts its axes its own way: the table path)."""
        if (
            ctl is None
            or type(n) is not int
            or extra
            or kw
            or session.remote is not None
            or session.core != 1
            or ctl.clock._thread is not None
        ):
            return None
        clk = clock_out(ctl, pClock)
        if clk is False:
            return None
        tp = type(p)
        if tp is _NDARRAY:  # (as the count-1 shape takes it: one C-contiguous writable row)
            if not (
                p.dtype in np_ok
                and p.ndim == 1
                and p.size >= count
                and p.flags.writeable
                and p.flags.c_contiguous
            ):
                return None
        elif not (is_array(tp) and tp._length_ >= count):
            return None
        if count > limit:
            if own_limit is None or ctl.card is not None:
                return None
            if not (_SHORT_MIN <= n <= _SHORT_MAX and count <= _SHORT_MAX):
                return None
            # more than the function reads at once (an encoder reader's 8): the table path
            # binds these plain arguments and the function refuses the count, the first thing
            # it checks (axis_span): the same code and reason without the table's steps
            return refuse(ctl, f"count={count}: at most {own_limit} at once")
        values = span(ctl, n, count, zeros)
        if values is None:
            return None
        p[:count] = values
        if clk is not None:
            clk[0].value = clk[1]
        session.last = None
        if ctl.clock.mode is not _LOCKSTEP:
            return advance(ctl, name, 0)
        return 0

    def span(ctl: Any, n: int, count: int, zeros: bool) -> Any:
        """The values of ``count`` axes from ``n`` (a sequence), None where the table path
        answers (an axis of the span neither on the bus nor, where ``zeros``, one of the
        controller's that no drive backs, which reads 0)."""
        if count > CONTROLLER_AXES and not 1 <= n <= n + count - 1 <= resource_count(ctl):
            return None  # (past the controller's axes: the table path's 7 and reason)
        resources = ctl.resources
        axes = ctl.axes
        b = ctl.bank
        if plan_key is not None and b is not None:
            # every axis of the span a row of the bank: its rows, found once while no row is
            # claimed or released (the bank's layout) and the controller's axes are the same
            # (an axis the controller has but no drive backs: 0, where ``zeros``)
            key = (plan_key, n, count, zeros)
            plan = b.read_plans.get(key)
            if (
                plan is None
                or plan[0] != b.layout
                or plan[1] is not resources
                or plan[2] is not axes
            ):
                top = resource_count(ctl) if zeros and axes else 0
                plan = _read_plan(b, resources, axes, n, count, top, get, row_expr, quick, source)
                b.read_plans[key] = plan
            pick = plan[3]
            if pick is not None and row_expr is not None:
                return pick(b)  # (the rows' values from the bank itself)
            if pick is not None:
                lst = b._lists.get(bank_key)
                if lst is not None or plan[4] is None:  # (no row of the bank: no list)
                    return pick(lst)
                # not made yet this cycle: the bank makes it (the list the first row's
                # getter reads its value from: AxisResources' properties of BANK_LISTS)
                b.value(bank_key, plan[4].bank_row)
                lst = b._lists.get(bank_key)
                if lst is not None:
                    return pick(lst)
        values: list[Any] = []
        append = values.append
        bank = lst = None
        top = 0  # the controller's axis count, once an axis of the span has no drive
        for k in range(n, n + count):
            if k not in axes and zeros:
                # an axis the controller has but no drive backs reads as one at rest (0),
                # as the table path's axis_span has it; a span past the controller's axes,
                # or no axis at all yet: the table path says why
                if not top:
                    top = resource_count(ctl) if axes else -1
                if not 1 <= n <= n + count - 1 <= top:
                    return None
                append(0)
                continue
            res = resources.get(k)
            if res is None or axes.get(k) is not res.ax:
                return None
            b = res.bank
            if b is None or bank_key is None:
                append(get(res))
                continue
            if b is not bank:  # (a bank's list of the value: one look-up for its axes)
                bank = b
                lst = b._lists.get(bank_key)
                if lst is None:  # not made yet this cycle: the getter makes it
                    append(get(res))
                    lst = b._lists.get(bank_key)
                    if lst is None:
                        bank = None
                    continue
            append(lst[res.bank_row])  # type: ignore[index]
        return values

    env["general"] = general

    def gtn_general(
        core: Any, n: Any, p: Any, count: Any, pClock: Any, extra: tuple, kw: dict
    ) -> int:
        if (
            type(core) is int
            and core > 1
            and type(n) is int
            and type(count) is int
            and 1 < count <= limit  # (a count the function refuses: the table path)
            and 0 < n
            and n + count - 1 <= AXES_PER_CORE
            and session.local
            and core not in session.controllers
        ):
            # count axes of a core beyond 32 axes (a view of core 1's bus): core 1's own way
            # with the bus axes, where it answers (else the table path of that core)
            q = p if type(p) is not _CArg else (array_at(p) or p)  # (as general)
            rc = many(
                session.controllers.get(1), n + AXES_PER_CORE * (core - 1), q, count, pClock,
                extra, kw, zeros=False,
            )  # fmt: skip
            if rc is not None:
                return rc
        args = [a for a in (core, n, p, count, pClock) if a is not _NO]
        return public[0].gtn_slow(*args, *extra, **kw)  # (set by gt_function)

    env["gtn_general"] = gtn_general
    public: list[Any] = [None]  # the public function (the C entry, else gt below)
    env["PUBLIC"] = public
    #: the GTN_ twin with core 1: the same fast path (GT_SetCore does not matter: it names
    #: its core); every other shape: the table's GTN_ function (set by gt_function)
    gt.gtn = _compiled(_READER, "gtn", env, core="core=_NO, ", session="session.local")  # type: ignore[attr-defined]
    gt.slow = slow  # type: ignore[attr-defined]  # the table path (tests compare both)
    public[0] = gt
    packers: dict[tuple[Any, int, str], Callable[..., bytes]] = {}

    def array_value(value: Callable[[Any], Any], gate: int) -> Callable[..., Any]:
        """The C entry's values for a ctypes array: ``f(n, count, array type, None)``
        gives the bytes of ``count`` values from axis ``n`` (``value(n)``'s for one; a span
        of axes too, as ``many`` answers them, of the controller behind ``gate``: 0 the GT_
        form's, 1 the GTN_ form's core 1), else _NO (the Python path answers).  A pClock's
        value the entry writes itself (GT_GetClock's: the controller's time and GT_Reset's,
        ``centry.set_clock_ms``)."""

        #: the last shape's array type, count and packer (a polling loop repeats its shape),
        #: whether its values are integers, whether native doubles (a float64 array's bytes)
        last: list[Any] = [None, 0, None, False, False]
        #: the last integers packed: the packer, the values, their bytes, and where they
        #: were picked from a list of the bank by a plan of its rows and zeros alone: that
        #: list and the plan's getter (else None)
        packed: list[Any] = [None, None, b"", None, None]
        #: per span (n, count) a plan of the bank answered last (span()'s, with a row of the
        #: bank): the bank, n, count, the layout, resources and axes it holds for, its pick,
        #: whether that picks the bank's rows and zeros alone (no other axis's getter), the
        #: getter of the bytes of the run of rows it picks in order (AxisBank.span_bytes,
        #: else None), the plan's getter of where its rows' values come from (_read_plan's,
        #: else None).  A span each: a program that reads two spans in turn
        #: (``GT_GetEncPos(1, a, 8)``, ``GT_GetEncPos(9, byref(a, 64), 4)``) finds both
        lanes: dict[tuple[int, int], list[Any]] = {}
        _CACHES.append(lanes)

        def f(n: int, count: int, tp: type, clock: Any) -> Any:
            # (a shape seen before: its packer, kept only for an array the reader takes)
            seen = last  # (one read: another thread may replace it meanwhile)
            if tp is seen[0] and count == seen[1]:
                pack, ints, doubles = seen[2], seen[3], seen[4]
            else:
                if type(tp) is not _ARRAY_META:
                    # a numpy array's dtype (the entry checked its array: one C-contiguous
                    # writable row of at least ``count`` elements, as ``many`` takes it)
                    if not (tp in np_ok and 2 <= count <= limit):
                        return _NO
                    code = tp.char
                else:
                    if not (is_array(tp) and 1 <= count <= tp._length_):
                        return _NO
                    code = tp._type_._type_  # (the array's own element type, natively)
                pack = packers.get((tp, count, code))
                if pack is None:
                    pack = struct.Struct(f"@{count}{code}").pack
                    packers[tp, count, code] = pack
                ints = code in _INT_CODES  # (not floats: -0.0 == 0.0)
                doubles = code == "d"
                last[:] = [tp, count, pack, ints, doubles]
            if clock is not None:  # (the entry writes a pClock itself: asked without)
                return _NO
            lst = pick = None  # (the bank's list and a plan's getter the values come from)
            words = False  # (status words of the bank's rows and zeros alone: (bytes,))
            recipe = None  # (a getter of where the values come from: the entry's gather)
            source = None  # (... or where they come from)
            if count == 1:
                v = value(n)
                if v is _NO:
                    return _NO
                if type(v) is tuple:
                    # (word,): a bank's status word, which stands as a span of them does;
                    # (x, op, ...): a double and where it comes from, made again as a span's
                    words = len(v) == 1
                    source = v[1:] if len(v) == 7 and doubles else None
                    v = v[0]
                values: Any = (v,)
            else:
                if count > limit:
                    return _NO
                # (an entry asks only while its gate is open: that gate's controller)
                ctl = GATED[gate]
                b = ctl.bank
                ln = lanes.get((n, count), _NO_LANE)  # (each lane is replaced whole)
                if (
                    ln[0] is b
                    and b is not None
                    and ln[3] == b.layout
                    and ln[4] is ctl.resources
                    and ln[5] is ctl.axes
                ):
                    # the span of the last call, its plan as span() finds it (the same
                    # checks): the bank's list of the cycle, made where it is not yet (a
                    # reader of BANK_ROWS: the rows' values from the bank itself)
                    words = status and ln[7]
                    if row_expr is not None:
                        values = ln[6](b)
                        recipe = ln[9]
                    else:
                        lists = b._lists
                        lst = lists.get(bank_key)
                        if lst is None and doubles and ln[8] is not None:
                            # a run of rows in order, not made yet this cycle: their bytes
                            # from the bank's arrays in one step (the same doubles as the
                            # list's, packed natively), no list of every row; with the
                            # arrays they come from (the entry gathers them again after
                            # the cycles it books itself: csrc/centry.c gather)
                            got = ln[8](b)
                            if got is not None:
                                session.last = None
                                return got if len(got) > 1 else got[0]
                        if lst is None:  # (AxisBank.value's making of it, without its frame)
                            lst = lists[bank_key] = b._make_list(bank_key)
                        memo = packed  # (one read: another thread may replace it meanwhile)
                        if lst is memo[3] and ln[6] is memo[4] and pack is memo[0]:
                            # the list the bank kept (its status words stand: AxisBank
                            # _sts_epoch), the same plan of its rows and zeros: the same values
                            values = memo[1]
                        else:
                            values = ln[6](lst)
                            pick = ln[6] if ln[7] else None
                else:
                    values = None
                if values is None:
                    values = span(ctl, n, count, True)
                    if values is None:
                        return _NO
                    plan = None if b is None else b.read_plans.get((plan_key, n, count, True))
                    if (
                        plan is not None
                        and plan[3] is not None
                        and plan[4] is not None
                        and plan[0] == b.layout
                        and plan[1] is ctl.resources
                        and plan[2] is ctl.axes
                    ):
                        run = plan[7]
                        if len(lanes) >= _LANES:  # (a program of many spans: the latest)
                            lanes.clear()
                        lanes[n, count] = [
                            *(b, n, count, *plan[:4], plan[6]),
                            None if run is None else b.span_bytes(bank_key, run),
                            plan[8],
                        ]
            memo = packed  # (one read: another thread may replace it meanwhile)
            if pack is memo[0] and (values is memo[1] or values == memo[1]):
                out = memo[2]  # (integers the same: the same bytes; a poll of idle axes)
                if pick is not None:  # (picked from another list: that list kept)
                    packed[:] = [pack, values, out, lst, pick]
            else:
                try:
                    out = pack(*values)
                except struct.error:  # (a value the element does not hold: the Python path)
                    return _NO
                if ints:
                    packed[:] = [pack, values, out, lst if pick is not None else None, pick]
            session.last = None
            if recipe is not None and doubles:  # (the entry makes them again: gather)
                source = recipe(b)
            if source is not None:
                return (out, *source)
            # status words of the bank's rows and zeros alone stand across the cycles the C
            # entry books that keep every flag (csrc/centry.c array_value)
            return (out,) if words else out

        return f

    if CENTRY:  # the common shape in C where it is available (gtecat.gt.centry)
        env["NOPE"] = _NO
        kind = centry.DOUBLE if ctypes_ok is _DOUBLE else centry.INT
        types = sorted(ctypes_ok, key=str)
        _gated(env)
        value_gt = _value_function(env, "value_gt", "CTL")
        value_gtn = _value_function(env, "value_gtn", "CTLN")

        seen_view: list[Any] = [None, None]  # (the last view asked and its answer)

        def viewer(v: memoryview) -> Any:
            """memoryview(arr) of a whole array this reader takes: arr (view_array)."""
            if v is seen_view[0]:  # (a view's object, format and size never change)
                try:
                    return seen_view[1] if v.obj is not None else None
                except ValueError:  # (released since: the table path says why)
                    return None
            q = view_array(v)
            q = q if is_array(type(q)) else None
            seen_view[:] = v, q  # (held: its id is not another's while it is here)
            return q

        entry = centry.reader(
            gt, value_gt, _NO, types, kind,
            pointers=True,  # (pointer(x): as general answers it)
            array=array_value(value_gt, 0), gate=centry.GT_GATE,
            after=_after(advance, name, 0),
            clocks=CLOCK_ORDER if takes_clock else (),
            numpy=sorted(np_ok, key=str),  # (the first element, as general writes it)
            steady=name in STEADY, viewer=viewer,
        )  # fmt: skip
        entry_gtn = centry.reader(
            gt.gtn, value_gtn, _NO, types, kind,
            core=True, pointers=True, array=array_value(value_gtn, 1),
            clocks=CLOCK_ORDER if takes_clock else (),
            gate=centry.GTN_GATE, after=_after(advance, name, 1),
            numpy=sorted(np_ok, key=str), steady=name in STEADY,
        )  # fmt: skip
        if entry is not None and entry_gtn is not None:
            entry.gtn, entry.slow, entry.python = entry_gtn, slow, gt  # type: ignore[attr-defined]
            public[0] = entry
            env["GTN_ENTRY"][0] = entry_gtn  # (a view core's axis: gt.gtn hands it there)
    return public[0]  # type: ignore[no-any-return]


#: the C entry of the readers where it is available (``GTECAT_CENTRY=0`` turns it off when
#: gtecat is imported; tests turn it off to hold the Python fast functions to the same answers)
CENTRY = os.environ.get("GTECAT_CENTRY", "1") != "0"


class _Off:
    """The controller a gated value function sees while its gate is closed: no axis, no
    input (its C entry does not ask it then; a direct call answers _NO)."""

    resources: dict = {}  # noqa: RUF012 - never written
    axes: dict = {}  # noqa: RUF012
    input_plans: dict = {}  # noqa: RUF012
    master = bank = card = None


_OFF = _Off()
#: the controllers behind the two gates (centry.GATES): the GT_ functions', the GTN_ ones'
#: (_OFF: closed); the globals ``CTL`` and ``CTLN`` of every gated value function's module
GATED: list[Any] = [_OFF, _OFF]
_GATED_ENVS: list[dict[str, Any]] = []


def _gated(env: dict[str, Any]) -> dict[str, Any]:
    """``env`` (a gated value function's globals) given the gates' controllers, and kept
    up to date by :func:`set_gates`."""
    env["CTL"], env["CTLN"] = GATED
    _GATED_ENVS.append(env)
    return env


def set_gates(gt: Any, gtn: Any, views: bool = False) -> None:
    """The session's answer (gtecat.gt._core: wherever it can change): ``gt`` the
    in-process lockstep or auto controller the GT_ functions address with core 1, ``gtn`` the GTN_
    functions' core 1, or None; ``views``: the GTN_ functions' cores 2.. are views of that
    core's bus (the C entries answer them by the bus axis).  The gated value functions read it
    as ``CTL`` / ``CTLN``, their C entries' gates open for it."""
    new = [_OFF if gt is None else gt, _OFF if gtn is None else gtn]
    if new[0] is GATED[0] and new[1] is GATED[1]:  # (the same: a client's call's select)
        if bool(centry.GATES[2]) != (views and gtn is not None):
            centry.GATES[2] = int(views and gtn is not None)
        return
    centry.set_gates(centry.CLOSED, centry.CLOSED)
    GATED[:] = new
    for cache in _CACHES:
        cache.clear()
    for env in _GATED_ENVS:
        env["CTL"], env["CTLN"] = GATED
    gates = _gate_value(gt), _gate_value(gtn)
    auto = [g == centry.AUTO for g in gates]
    centry.set_clocks(
        *(c.clock if a else None for c, a in zip(new, auto, strict=True)),
        calls=tuple(_quick_calls(c) if a else None for c, a in zip(new, auto, strict=True)),  # type: ignore[arg-type]
        books=tuple(
            getattr(c, "quick_cbook", None) if a else None for c, a in zip(new, auto, strict=True)
        ),  # type: ignore[arg-type]
    )
    centry.set_locks(
        *(c.clock if g != centry.CLOSED else None for c, g in zip(new, gates, strict=True))
    )
    centry.set_clock_ms(
        *(c if g != centry.CLOSED else None for c, g in zip(new, gates, strict=True))
    )
    centry.set_wait(gt if gates[0] != centry.CLOSED else None)
    centry.set_gates(*gates, views)


#: the GT layer's turn of what a cycle raised into the call's code and reason
#: (gtecat.gt._core.cycle_failed, set there): ``failed(name, exception, rc) -> code``
CYCLE_FAILED: list[Callable[[str, Exception, int], int]] = []


def _quick_calls(ctl: Any) -> Any:
    """``ctl``'s book of its armed quick cycle for the C entries (centry.CLOCK_CALLS):
    ``book(after, rc)`` (Controller.quick_book, whatever it raises turned into the call's
    code as advance turns it); None: none."""
    quick_book = getattr(ctl, "quick_book", None)
    if quick_book is None or not CYCLE_FAILED:
        return None
    failed = CYCLE_FAILED[0]

    def book(after: Any, rc: int) -> int:
        try:
            quick_book(rc)
        except Exception as e:
            return failed(getattr(after, "gt_name", "GT call"), e, 0)
        return 0

    return book


def _gate_value(ctl: Any) -> int:
    """A gate's value for the controller behind it (None: closed)."""
    if ctl is None:
        return centry.CLOSED
    return centry.LOCKSTEP if ctl.clock.mode is _LOCKSTEP else centry.AUTO


def _after(advance: Callable[[Any, str, int], int], name: str, k: int) -> Callable[[], int]:
    """An entry's ``after`` (:func:`centry.reader`): in the auto clock the call's host
    latency once its value is written, as the Python path's ``advance`` runs it (its
    cycles may run; what they raise becomes the call's code), on gate ``k``'s controller."""

    def after() -> int:
        return advance(GATED[k], name, 0)

    after.gt_name = name  # type: ignore[attr-defined]  # (a quick cycle's errors name the call)
    return after


def _entry(
    gt: Any,
    value: Callable[[Any], Any],
    types: Any,
    kind: int,
    size: int = 0,
    gate: int = centry.NO_GATE,
    after: Callable[[], int] | None = None,
    array: Callable[..., Any] | None = None,
) -> Any:
    """A two-argument reader's public function: its C entry in front of its Python fast
    function ``gt`` (:func:`centry.reader`: ``value(n)`` the value, or ``_NO``), where
    :data:`CENTRY` is on and the entry is available; else ``gt``; ``gate``: as
    :func:`centry.reader`'s; ``array``: its ``array`` (an integer reader's: the first
    element's, made here)."""
    if not CENTRY:
        return gt
    numpy: list[Any] = []
    if kind == centry.INT:  # (an integer reader: its integer types; any other, the Python)
        types = [t for t in types if getattr(t, "_type_", "") in _INT_CODES]
        numpy = _int_dtypes(types)  # (the Python path's numpy shape: _array_first)
        array = _first_element(value, types)
    entry = centry.reader(
        gt, value, _NO, sorted(types, key=str), kind, most=2, size=size, gate=gate,
        after=after, numpy=numpy, array=array,
    )  # fmt: skip
    if entry is None:
        return gt
    entry.slow, entry.python = gt.slow, gt
    return entry


#: the ctypes type codes of the integers an entry writes (of 1 to 8 bytes, either sign)
_INT_CODES = frozenset("bBhHiIlLqQ")


def _first_element(value: Callable[[Any], Any], types: Any) -> Callable[..., Any]:
    """A two-argument reader's values for a ctypes array (:func:`centry.reader`'s ``array``):
    an array of one of ``types`` with at least one element takes ``value(n)`` in its first
    element, as the Python fast paths' :func:`_array_first` has it; else _NO."""
    ok = frozenset(types)
    packers: dict[type, Callable[..., bytes]] = {}

    def f(n: Any, count: Any, tp: type, clock: Any) -> Any:
        if count != 1 or clock is not None:
            return _NO
        pack = packers.get(tp)
        if pack is None:
            if not (issubclass(tp, ctypes.Array) and tp._length_ >= 1 and tp._type_ in ok):
                return _NO
            pack = packers[tp] = struct.Struct("@" + tp._type_._type_).pack
        v = value(n)
        if v is _NO:
            return _NO
        try:
            return pack(v)
        except struct.error:  # (a value the element does not hold: the Python path)
            return _NO

    return f


#: a reader's value of an axis the bank does not run, inline (without the getter's call):
#: GT_GetSts's word as :meth:`AxisResources.status` makes it (the latched flags as they are:
#: an int; tests/gtecat/gt/test_fast_shapes.py holds the two to the same word in every state
#: they combine, a Trap planner's and another planner's)
SCALAR_INLINE: dict[str, tuple[str, ...]] = {
    "GT_GetSts": (
        "v = res.latched",
        "if res.ax.servo_on:",
        "    v |= SERVO_ON",
        "pl = res.profile.planner",
        # the planner's done (a Trap planner's own state read without the property's call)
        "if (pl._mode != TRAP_IDLE) if type(pl) is TRAP else not pl.done:",
        "    v |= MOVING",
        "elif res.band.arrived:",
        "    v |= ARRIVED",
    ),
}
_STATUS_BITS = {
    "SERVO_ON": int(AxisStatus.SERVO_ON),
    "MOVING": int(AxisStatus.MOVING),
    "ARRIVED": int(AxisStatus.ARRIVED),
    "TRAP": TrapPlanner,
    "TRAP_IDLE": TRAP_IDLE,
}


def _linked(bank_list: str, own: str, from_bank: str) -> tuple[str, ...]:
    """The steps of a reader's value ``own`` (an axis the bank does not run), else
    ``from_bank`` of ``x``, the bank's value of the axis from its list ``bank_list``."""
    return (
        "b = res.bank",
        "if b is None:",
        f"    v = {own}",
        "else:",
        f"    lst = b._lists.get({bank_list!r})",
        f"    x = b.row_value({bank_list!r}, res.bank_row) if lst is None else lst[res.bank_row]",
        f"    v = {from_bank}",
    )


#: a reader's value of an axis the bank does not run (``res.bank`` None): the branch of the
#: AxisResources property of the reader's name for it (the planner's or the encoder's own
#: value), read without the property's call
UNBANKED: dict[str, str] = {
    "GT_GetPrfPos": "res.profile.planner.pos",
    "GT_GetPrfVel": "res.profile.planner.vel",
    "GT_GetPrfAcc": "res.profile.planner.acc",
    "GT_GetAxisPrfPos": "res.ax.prf_pos",
    "GT_GetEncPos": "res.encoder.pos",
    "GT_GetEncVel": "res.encoder.vel",
}


#: the readers whose value is a link applied to a profile's or an encoder's value, or a bit
#: of the status word (the AxisResources property or method the reader's getter calls, its
#: steps inline: the same operations in the same order): function -> the steps that set
#: ``v``; tests/gtecat/gt/test_fast_walk.py
#: holds each to its property, banked and not
DERIVED: dict[str, tuple[str, ...]] = {
    "GT_GetAxisPrfVel": _linked(
        "prf_v", "res.prf_link.ratio * res.profile.planner.vel", "res.prf_link.ratio * x"
    ),
    "GT_GetAxisPrfAcc": _linked(
        "prf_a", "res.prf_link.ratio * res.profile.planner.acc", "res.prf_link.ratio * x"
    ),
    "GT_GetAxisEncVel": _linked(
        "enc_vel", "res.enc_link.ratio * res.encoder.vel", "res.enc_link.ratio * x"
    ),
    "GT_GetAxisEncAcc": _linked(
        "enc_acc", "res.enc_link.ratio * res.encoder.acc", "res.enc_link.ratio * x"
    ),
    "GT_GetAxisEncPos": _linked(
        "enc_pos", "res.enc_link.axis(res.encoder.pos)", "res.enc_link.axis(x)"
    ),
    # GT_GetSts's word's planner bit (prf_sts_value: status() & MOVING)
    "GT_GetPrfSts": (
        "b = res.bank",
        "if b is None:",
        "    v = res.latched & MOVING",
        "    pl = res.profile.planner",
        "    if (pl._mode != TRAP_IDLE) if type(pl) is TRAP else not pl.done:",
        "        v = MOVING",
        "else:",
        "    lst = b._lists.get('sts')",
        "    v = (b.row_value('sts', res.bank_row) if lst is None else lst[res.bank_row]) & MOVING",
    ),
    # the axis's planned position less its encoder's through the link (axis_error)
    "GT_GetAxisError": (
        "b = res.bank",
        "if b is None:",
        "    v = res.ax.prf_pos - res.enc_link.axis(res.encoder.pos)",
        "else:",
        "    row = res.bank_row",
        "    lst = b._lists.get('a_last')",
        "    x = b.row_value('a_last', row) if lst is None else lst[row]",
        "    lst = b._lists.get('enc_pos')",
        "    v = x - res.enc_link.axis(b.row_value('enc_pos', row) if lst is None else lst[row])",
    ),
}

#: a banked axis's value of each DERIVED reader, one row of the bank alone as the value
#: function's DERIVED steps make it (AxisBank.row_value: the row's value, or the list's
#: where it is made already; the encoder's rates of a row and the positions of one, read
#: without row_value's frame, as it makes them in a bank of any size: the values its lists
#: hold): ``{R}`` the axis's resources, ``{r}`` its row; a span's plan (_read_plan) writes
#: one per row, so a span after a cycle does not make every row's list of the value
#: (tests/gtecat/gt/test_fast_span_rows.py).  The status word comes from the bank's list
#: (AxisBank.value): its words stand across a cycle that moves no flag (AxisBank
#: _sts_epoch), cheaper than each row's word made from its flags for two rows already
BANK_ROWS: dict[str, str] = {
    "GT_GetAxisPrfVel": "{R}.prf_link.ratio * b.row_value('prf_v', {r})",
    "GT_GetAxisPrfAcc": "{R}.prf_link.ratio * b.row_value('prf_a', {r})",
    "GT_GetAxisEncVel": "{R}.enc_link.ratio * b._enc_rates_row({r})[0]",
    "GT_GetAxisEncAcc": "{R}.enc_link.ratio * b._enc_rates_row({r})[1]",
    "GT_GetAxisEncPos": "{R}.enc_link.axis(b.enc_pos.item({r}))",
    "GT_GetPrfSts": "b.value('sts', {r}) & MOVING",
    "GT_GetAxisError": "b.a_last.item({r}) - {R}.enc_link.axis(b.enc_pos.item({r}))",
}

#: a reader of BANK_LISTS whose span is written from each row alone, as BANK_ROWS' are:
#: the encoder's speed (the bank's list of it is made with every row's acceleration too)
SPAN_ROWS: dict[str, str] = {"GT_GetEncVel": "b._enc_rates_row({r})[0]"}

#: a quicker form of a span's row values of BANK_ROWS and SPAN_ROWS (a span after a cycle
#: writes one per row): (the names it reads from the bank ``b``, what must hold of the whole
#: bank, what must hold of a row ``{r}``, the row's value then): the same IEEE operations on
#: the same doubles as the row's expression, in the case the guard names (the planned values
#: of a bank where no row jogs or homes: AxisBank._planned_one; encoder rates of a row
#: claimed two cycles ago or more: AxisBank._enc_rates_row), without its calls' frames; the
#: row's expression where a guard fails (tests/gtecat/gt/test_fast_span_rows.py)
_PRF_QUICK = "i = b.t_idx", "not (b.n_jog or b.n_hm)", "True"
_ENC_QUICK = (
    "T = b.T; now = b.counts[3]; c = b.claim_cycle; s1 = b.enc_step1; s0 = b.enc_step0",
    "True",
    "now - c.item({r}) >= 2",
)
QUICK_ROWS: dict[str, tuple[str, str, str, str]] = {
    "GT_GetAxisPrfVel": (*_PRF_QUICK, "{R}.prf_link.ratio * b._t_v1.item(i.item({r}))"),
    "GT_GetAxisPrfAcc": (*_PRF_QUICK, "{R}.prf_link.ratio * b._t_a1.item(i.item({r}))"),
    "GT_GetAxisEncVel": (*_ENC_QUICK, "{R}.enc_link.ratio * (s1.item({r}) / T)"),
    "GT_GetAxisEncAcc": (
        *_ENC_QUICK,
        "{R}.enc_link.ratio * ((s1.item({r}) / T - s0.item({r}) / T) / T)",
    ),
    "GT_GetEncVel": (*_ENC_QUICK, "s1.item({r}) / T"),
}

#: the readers whose values no cycle changes (a Python attribute: a cycle the C entries book
#: themselves runs no Python): their entries keep them across such cycles (centry.reader's
#: ``steady``)
STEADY = frozenset({"GT_GetPrfMode"})

#: one banked axis's double that its C entry makes again itself after the cycles it books
#: (csrc/centry.c kept: the operations of QUICK_SOURCES on the axis's row ``res.bank_row``):
#: (op, the bank's arrays src and idx, the factor or None, where the value function's
#: value is that: its guard, which holds on across such cycles)
_NO_JOG = "not (b.n_jog or b.n_hm)"
_CLAIMED = "b.counts[3] - b.claim_cycle.item(res.bank_row) >= 2"
SCALAR_SOURCES: dict[str, tuple[int, str, str | None, str | None, str]] = {
    "GT_GetPrfPos": (0, "_t_p1", "t_idx", None, _NO_JOG),
    "GT_GetPrfVel": (0, "_t_v1", "t_idx", None, _NO_JOG),
    "GT_GetPrfAcc": (0, "_t_a1", "t_idx", None, _NO_JOG),
    "GT_GetAxisPrfPos": (0, "a_last", None, None, "True"),
    "GT_GetEncPos": (0, "enc_pos", None, None, "True"),
    "GT_GetEncVel": (1, "enc_step1", None, None, _CLAIMED),
    "GT_GetAxisPrfVel": (0, "_t_v1", "t_idx", "res.prf_link.ratio", _NO_JOG),
    "GT_GetAxisPrfAcc": (0, "_t_a1", "t_idx", "res.prf_link.ratio", _NO_JOG),
    "GT_GetAxisEncVel": (1, "enc_step1", None, "res.enc_link.ratio", _CLAIMED),
    "GT_GetAxisEncAcc": (2, "enc_step1", "enc_step0", "res.enc_link.ratio", _CLAIMED),
    "GT_GetAxisEncPos": (3, "enc_pos", None, "res.enc_link", "True"),
    "GT_GetAxisError": (4, "a_last", "enc_pos", "res.enc_link", "True"),
}
_PACK_D = struct.Struct("@d").pack
_PACK_D2 = struct.Struct("@2d").pack
_ROWS8: dict[int, bytes] = {}


def _row8(r: int) -> bytes:
    """Row ``r`` as the int64 bytes a C entry reads (SCALAR_SOURCES' rows)."""
    b = _ROWS8.get(r)
    if b is None:
        b = _ROWS8[r] = array("q", (r,)).tobytes()
    return b


#: the QUICK_ROWS values a span's C entry makes again itself after the cycles it books
#: (csrc/centry.c gather: the same IEEE operations in the same order on the bank's arrays,
#: which the compiled cycle moves in place): (its op - 0 ``src[idx[r]]``, 1 ``src[r] / T``,
#: 2 ``(src[r] / T - idx[r] / T) / T`` -, the bank's arrays src and idx, the factor of the
#: axis's resources or None); asked where QUICK_ROWS' guards hold (which hold on across
#: such cycles: no row jogs or homes, a row claimed two cycles ago or more)
QUICK_SOURCES: dict[str, tuple[int, str, str | None, str | None]] = {
    "GT_GetAxisPrfVel": (0, "_t_v1", "t_idx", "prf_link.ratio"),
    "GT_GetAxisPrfAcc": (0, "_t_a1", "t_idx", "prf_link.ratio"),
    "GT_GetAxisEncVel": (1, "enc_step1", None, "enc_link.ratio"),
    "GT_GetAxisEncAcc": (2, "enc_step1", "enc_step0", "enc_link.ratio"),
    "GT_GetEncVel": (1, "enc_step1", None, None),
    # 3 ``axis(src[r])``, 4 ``src[r] - axis(idx[r])``: the encoder's link (AffineLink.axis,
    # its two branches) of each axis, its ratio and offset
    "GT_GetAxisEncPos": (3, "enc_pos", None, "enc_link"),
    "GT_GetAxisError": (4, "a_last", "enc_pos", "enc_link"),
}

#: a span's lane that holds for nothing (a reader's array_value: no span answered yet)
_NO_LANE = (None,) * 10
#: the spans a reader's array_value keeps lanes of at most
_LANES = 16

#: the most axes a reader answers in one call (the encoder readers: 8, section 8.2)
READ_LIMITS = {"GT_GetEncPos": 8, "GT_GetEncVel": 8}

#: the bank's list of each reader's value (AxisBank.value), read without the two calls
BANK_LISTS = {
    "GT_GetSts": "sts",
    "GT_GetPrfPos": "prf_p",
    "GT_GetPrfVel": "prf_v",
    "GT_GetPrfAcc": "prf_a",
    "GT_GetAxisPrfPos": "a_last",
    "GT_GetEncPos": "enc_pos",
    "GT_GetEncVel": "enc_vel",
}


def _read_plan(
    b: Any,
    resources: Any,
    axes: Any,
    n: int,
    count: int,
    top: int = 0,
    get: Any = None,
    row: str | None = None,
    quick: tuple[str, str, str, str] | None = None,
    source: tuple[int, str, str | None, str | None] | None = None,
) -> tuple[Any, ...]:
    """(the bank's layout, the resources and axes looked at, a getter of the span's values
    from a list of the bank's values or None, the first row's resources or None when no axis
    of the span is a row of ``b``, that row's place in the span, whether the getter picks
    rows (of a list, or the bank's own) and zeros alone: the same list, the same values,
    the slice of the list's rows it picks where they are a run in order, else None:
    AxisBank.span_bytes).  Each axis of the span is a row of ``b``, an axis the bank does
    not run (its value ``get(resources)``, where ``get`` is given) or, within ``1..top``,
    an axis no drive backs (it reads 0); any other (another bank's axis, one not on the
    bus): no getter.  ``row``: a row's value is that expression of BANK_ROWS (``{R}`` its
    resources, ``{r}`` its row) and the getter takes the bank itself, not a list; ``quick``:
    QUICK_ROWS' form of it, taken where its guards hold; ``source``: QUICK_SOURCES' for it,
    and the plan's last item a function of the bank giving where the values come from where
    those guards hold (``(op, src, idx, rows, ratios, T)``, csrc/centry.c gather), else
    None."""
    none = (b.layout, resources, axes, None, None, 0, False, None, None)
    if count < 2:  # (one value: no tuple to store)
        return none
    items: list[str] = []
    quick_items: list[str] = []
    guards: list[str] = [] if quick is None else [quick[1]]
    env: dict[str, Any] = {"g": get}
    at = None
    rows: list[int] = []  # (the bank's rows of the span, in order: a source's)
    for i, k in enumerate(range(n, n + count)):
        if k not in axes and 1 <= n <= n + count - 1 <= top:
            items.append("0")
            quick_items.append("0")
            continue
        res = resources.get(k)
        if res is None or axes.get(k) is not res.ax:
            return none
        if res.bank is b:
            if row is None:
                items.append(f"lst[{res.bank_row}]")
            else:
                items.append(row.format(R=f"r{i}", r=res.bank_row))
                env[f"r{i}"] = res
                if quick is not None:
                    quick_items.append(quick[3].format(R=f"r{i}", r=res.bank_row))
                    guards.append(quick[2].format(r=res.bank_row))
            rows.append(res.bank_row)
            at = i if at is None else at
        elif res.bank is None and get is not None:
            items.append(f"g(r{i})")
            quick_items.append(f"g(r{i})")
            env[f"r{i}"] = res
        else:
            return none
    # (rows and zeros alone: no getter of another axis)
    pure = not any(x.startswith("g(") for x in items)
    run = None
    if pure and row is None and at is not None and "0" not in items:
        rows = [int(x[4:-1]) for x in items]
        pick = itemgetter(*rows)
        if rows == list(range(rows[0], rows[0] + count)):
            run = slice(rows[0], rows[0] + count)
    else:  # (the rows, the getters and the zeros in one tuple)
        env["MOVING"] = _STATUS_BITS["MOVING"]
        arg = "lst" if row is None else "b"
        pick = eval(_plan_code(f"lambda {arg}: ({', '.join(items)},)", "eval"), env)
        if quick is not None and at is not None:
            env["slow"] = pick
            guard = " and ".join(x for x in guards if x != "True") or "True"
            exec(
                _plan_code(
                    f"def quick(b):\n    {quick[0]}\n    if {guard}:\n"
                    f"        return ({', '.join(quick_items)},)\n    return slow(b)\n",
                    "exec",
                ),
                env,
            )
            pick = env["quick"]
    from_source = None
    if source is not None and pure and len(rows) == count:
        op, src, idx, factor = source
        if factor is not None and factor.endswith("_link"):  # (a link's axis(): both)
            f = ", ".join(f"r{i}.{factor}.ratio, r{i}.{factor}.offset" for i in range(count))
            width = 2 * count
        else:
            f = ", ".join(f"r{i}.{factor}" for i in range(count)) if factor else ""
            width = count
        env |= {"ROWS": array("q", rows).tobytes(), "_pack": struct.Struct(f"@{width}d").pack}
        env |= {"_num": (int, float)}
        guard = " and ".join(x for x in guards if x != "True") or "True"
        exec(
            _plan_code(
                f"def from_source(b):\n    {quick[0] if quick is not None else 'pass'}\n"
                f"    if not ({guard}):\n        return None\n"
                + (
                    f"    f = ({f},)\n"
                    "    if not all(type(x) in _num for x in f):\n        return None\n"
                    "    f = _pack(*f)\n"
                    if factor
                    else "    f = None\n"
                )
                + f"    t = b.T if {op} in (1, 2) else 0.0\n"
                + "    if type(t) is not float:\n        return None\n"
                + f"    return {op}, b.{src}, {'b.' + idx if idx else 'None'}, ROWS, f, t\n",
                "exec",
            ),
            env,
        )
        from_source = env["from_source"]
    first = None if at is None else resources.get(n + at)
    return (b.layout, resources, axes, pick, first, at, pure, run, from_source)


#: the plans' getters compiled, by their text (:func:`_plan_code`)
_PLAN_CODES: dict[tuple[str, str], Any] = {}


def _plan_code(text: str, mode: str) -> Any:
    """A plan's getter compiled once per text: a bank whose layout changes back and forth
    (axes claimed and released as links go down and come back, homings start and end) makes
    the same plans again, each a compile of ~50-100 us where the code is kept."""
    code = _PLAN_CODES.get((text, mode))
    if code is None:
        if len(_PLAN_CODES) >= 512:
            _PLAN_CODES.clear()
        code = _PLAN_CODES[text, mode] = compile(text, "<read plan>", mode)
    return code


#: the common shape of a reader (``GT_GetSts(axis, p)``, ``p`` a byref or the object) in the
#: fewest steps, compiled for the GT_ function and its GTN_ twin; anything else: general
_READER = """
def {fname}({core}n=_NO, p=_NO, count=_NO, pClock=_NO, /, *extra, **kw):
    global LAST_P  # the last byref object checked (kept alive, so never another's address){viewed}
    if (
        type(n) is int
        and not kw
        and not extra{core_check}
        and (
            count is _NO
            or (
                type(count) is int
                and count == 1
                # pClock NULL: omitted, None or 0 (the manual's own GT_GetSts(1, &s, 1, 0))
                and (pClock is _NO or pClock is None or (type(pClock) is int and pClock == 0))
            )
        )
    ):
        try:  # (two subscripts: cheaper than two get calls)
            ctl = session.controllers[1]
            res = ctl.resources[{bus_axis}]
        except KeyError:  # no controller, or no such axis: the table path says why
            return {fallback}
        clock = ctl.clock
        if {session} and clock._thread is None:
            tp = type(p)
            if tp is _CArg:
{byref}
            elif tp is T0 or tp in ok:  # the ctypes object itself (by reference)
                obj = p
            elif (
                tp is _NDARRAY
                and p.dtype in np_ok
                and p.ndim == 1
                and p.size
                and p.flags.writeable
                and p.flags.c_contiguous  # (a strided view: the table path's 7)
            ) or is_array(tp):  # a numpy or ctypes array: its first element
                obj = None
            else:
                return {fallback}{delegate}
{{value}}
            if obj is None:
                p[0] = v
            else:
                obj.value = v
            session.last = None
            if clock.mode is _LOCKSTEP:
                return 0
            return advance(ctl, name, 0)
    return {fallback}
"""


#: the byref branch of a reader: its object when the pointer passes the object's own address
#: and the type is one the reader writes (one C call, :mod:`gtecat.gt.byref_target`) ...
_BYREF_C = """\
                obj = TARGET(p)
                if obj is p:  # byref(array[, offset]): the element there (C's &array[k]) ...
                    obj = element_at(p, ok)
                    if obj is None:  # ... else byref(obj, offset), another type: the table
                        return {fallback}"""
#: ... or, where that is not available, read from Python (a reused pointer checked once)
_BYREF_PY = """\
                obj = p._obj
                if p is not LAST_P:
                    # byref(obj), not byref(obj, offset); any doubt: the table path
                    kind = type(obj)
                    if (kind is not T0 and kind not in ok) or {address} != _addressof(obj):
                        obj = element_at(p, ok)  # (byref(array[, offset]): C's &array[k])
                        if obj is None:
                            return {fallback}
                    elif _refs(p) > KEPT:  # the caller keeps it (a reused pointer):
                        LAST_P = p  # checked, the same object next time needs no check"""


def _byref_check(env: dict[str, Any], types: frozenset) -> str:
    """The byref branch's source for a reader of ``types`` (its names go into ``env``)."""
    env.update(CARG_ENV)
    env["element_at"] = element_at
    if BYREF_TARGET:
        f = byref_target.target(types)
        if f is not None:
            env["TARGET"] = f
            return _BYREF_C
    return _BYREF_PY


#: the byref check in C where it is available (tests turn it off to hold the Python one to
#: the same answers)
BYREF_TARGET = True


def _target(types: Any) -> Callable[[Any], Any]:
    """``f(p)`` with :func:`byref_target.target`'s answers (``p``'s object when ``p`` is a
    ``byref`` of an object of one of ``types`` passing that object's own address, else
    ``p``): the C check where it is available and :data:`BYREF_TARGET` is on, else the
    same check in Python, so a fast path has one branch for both."""
    f = byref_target.target(types) if BYREF_TARGET else None
    if f is not None:
        return f
    ok = frozenset(types)

    def target(p: Any) -> Any:
        if type(p) is not _CArg:
            return p
        obj = p._obj
        if type(obj) not in ok or byref_address(p) != _addressof(obj):
            return p
        return obj

    return target


#: the GTN_ form of a core beyond 32 axes (a view of core 1's bus), its shape one the Python
#: path takes: the GTN_ form's C entry with core 1 and the bus axis answers it (the same
#: controller, resources and value; its kept value, its cycles in C), where there is one;
#: a shape that entry hands on comes back here with core 1, which answers it as this core
#: would
_DELEGATE = """
            if core != 1:
                entry = GTN_ENTRY[0]
                if entry is not None:
                    if count is _NO:
                        return entry(1, n + PER_CORE * (core - 1), p)
                    if pClock is _NO:
                        return entry(1, n + PER_CORE * (core - 1), p, count)
                    return entry(1, n + PER_CORE * (core - 1), p, count, pClock)"""


#: the GT_ form's ``memoryview(arr)`` of a whole ctypes array: the public function (its C
#: entry) called with that array (view_array)
_VIEWED = """
    if type(p) is memoryview and not kw and not extra and is_array(type(q := view_array(p))):
        if count is _NO:
            return PUBLIC[0](n, q)
        if pClock is _NO:
            return PUBLIC[0](n, q, count)
        return PUBLIC[0](n, q, count, pClock)"""


def _compiled(template: str, fname: str, env: dict[str, Any], core: str, session: str) -> Any:
    """``template`` made a function (the GT_ form, or the GTN_ form with ``core`` first)."""
    address = carg_address_source("p")
    env.update(CARG_ENV)
    gtn = bool(core)
    template = template.replace("{byref}", _byref_check(env, env["ok"]))
    code = template.format(
        fname=fname,
        core=core,
        # core 1, or a core beyond 32 axes (a view of core 1's bus: its local axis n is bus
        # axis n + 32·(core-1), gtecat.controller.core_view) where no controller of its own
        # answers that core (a card's second core: the table path)
        core_check=(
            " and type(core) is int and (core == 1 or (core > 1 and 0 < n <= PER_CORE"
            " and core not in session.controllers))"
            if gtn
            else ""
        ),
        bus_axis="n if core == 1 else n + PER_CORE * (core - 1)" if gtn else "n",
        delegate=_DELEGATE if gtn else "",
        viewed="" if gtn else _VIEWED,
        session=session,
        address=address,
        fallback=(
            "gtn_general(core, n, p, count, pClock, extra, kw)"
            if gtn
            else "general(n, p, count, pClock, extra, kw)"
        ),
    )
    env["_AT"] = _AT
    env["PER_CORE"] = AXES_PER_CORE
    env.setdefault("GTN_ENTRY", [None])  # (the GTN_ form's C entry, once made)
    value = "\n".join("            " + line for line in _value_lines(env))
    code = code.replace("{value}", value)
    exec(_compiled_code(code, f"<gt fast {fname} {env['name']}>"), env)  # env: its globals
    return env[fname]


def _value_lines(env: dict[str, Any]) -> list[str]:
    """The steps that set ``v``, a reader's value of the axis ``res`` (the names they use
    go into ``env``): the fast function's and its C entry's value function's."""
    attr = getattr(env["get"], "attr", None)
    derived = DERIVED.get(env["name"])
    if derived is not None:  # (AxisResources' property, its steps inline)
        lines = [*derived]
        if env["to"] is float:
            lines += ["if type(v) is not float:", "    v = float(v)"]
        env.update(_STATUS_BITS)
        return lines
    if env["name"] in SCALAR_INLINE:
        scalar = list(SCALAR_INLINE[env["name"]])
        env.update(_STATUS_BITS)
    elif attr is None:
        scalar = ["v = get(res)"]
    else:  # the attribute itself (attr_getter's value, without the two calls)
        # (of an axis the bank does not run: the property's own branch for it, inline)
        own = f"res.{attr}"
        if env["key"] is not None:  # (the bank's own list otherwise, below)
            own = UNBANKED.get(env["name"], own)
        scalar = [f"v = {own}", "if type(v) is not float:", "    v = float(v)"]
    if env["key"] is None:
        return scalar
    # a banked axis's value from the bank's list (AxisBank.value), else the getter
    lines = [
        "b = res.bank",
        "if b is None:",
        *("    " + x for x in scalar),
        "else:",
        "    lst = b._lists.get(key)",
        "    v = b.row_value(key, res.bank_row) if lst is None else lst[res.bank_row]",
    ]
    if env["to"] is not None:  # (a double: the list's float as it is, else float())
        lines += ["    if type(v) is not float:", "        v = to(v)"]
    return lines


#: a reader's value for its C entry (:mod:`gtecat.gt.centry`): the value of axis ``n`` of the
#: in-process lockstep controller as the fast function writes it, with the fast function's
#: side effect (the last error cleared); NOPE where the fast function must answer
#: (the entry asks it only while its gate is open: ``{ctl}``, CTL or CTLN, is that controller)
_VALUE = """
def {fname}(n):
    try:
        res = {ctl}.resources[n]
    except KeyError:  # no such axis
        return NOPE
{{value}}
    session.last = None
    {{tail}}
"""


def _value_function(env: dict[str, Any], fname: str, ctl: str) -> Callable[[Any], Any]:
    """The value function of a reader's C entry (``ctl``: the GT_ or the GTN_ form's gated
    controller, ``CTL`` or ``CTLN``)."""
    value = "\n".join("    " + line for line in _value_lines(env))
    # a status word of the bank's as (word,): it stands across the quick cycles that keep
    # every flag (csrc/centry.c kept), as a span of them does
    status = env["name"] in ("GT_GetSts", "GT_GetPrfSts")  # (GT_GetPrfSts: a bit of it)
    tail = "return v if res.bank is None else (v,)" if status else "return v"
    source = SCALAR_SOURCES.get(env["name"])
    if source is not None:  # a double of the bank's with where it comes from (kept)
        op, src, idx, factor, guard = source
        t = "b.T" if op in (1, 2) else "0.0"
        env |= {"_ROW8": _row8, "_D": _PACK_D, "_D2": _PACK_D2, "_NUM": (int, float)}
        link = factor is not None and factor.endswith("_link")  # (a link's axis(): both)
        tail = "\n".join(
            [
                f"if b is not None and {guard} and type({t}) is float:",
                f"    f = {factor or 'None'}",
                *(
                    [
                        "    if type(f.ratio) in _NUM and type(f.offset) in _NUM:",
                        "        f = _D2(f.ratio, f.offset)",
                    ]
                    if link
                    else [
                        "    if f is None or type(f) in _NUM:",
                        "        f = None if f is None else _D(f)",
                    ]
                ),
                f"        return v, {op}, b.{src}, {'b.' + idx if idx else 'None'}, "
                f"_ROW8(res.bank_row), f, {t}",
                "return v",
            ]
        ).replace("\n", "\n    ")
    code = _VALUE.format(fname=fname, ctl=ctl).replace("{value}", value).replace("{tail}", tail)
    exec(_compiled_code(code, f"<gt fast {fname} {env['name']}>"), env)  # env: its globals
    return env[fname]  # type: ignore[no-any-return]


#: the clock reader on the fast path (``pClock``, ``pLoop`` NULL or omitted)
CLOCK = "GT_GetClock"
#: the largest value each integer type of ``_INTS`` holds
_INT_MAX = {t: (1 << (8 * ctypes.sizeof(t) - 1)) - 1 for t in _INTS}
#: the clock's integer types: the vendor's ``unsigned long *pClock`` (a Python caller's
#: ``c_ulong``) beside the signed ones (a clock past a ``c_int32``'s range: the table path,
#: which stores its bit pattern)
_CLOCK_INTS = _INTS | {ctypes.c_uint32, ctypes.c_ulong, ctypes.c_uint64, ctypes.c_ulonglong}
_INT_MAX.update(
    {t: (1 << (8 * ctypes.sizeof(t))) - 1 for t in _CLOCK_INTS - _INTS}  # (unsigned)
)
#: the clock's types in the order a C entry looks for them: the vendor's ``c_ulong`` and
#: ``c_uint32`` first (a poll's clock is found in one step), then the others
CLOCK_ORDER = sorted(
    _CLOCK_INTS, key=lambda t: (t is not ctypes.c_ulong, t is not ctypes.c_uint32, str(t))
)


_CLOCK_POINTERS: dict[type, bool] = {}


def clock_scalar(target: Callable[[Any], Any], p: Any) -> Any:
    """The integer a clock argument (``pClock``, GT_GetClock's ``pLoop``) writes: ``x`` for
    ``byref(x)`` (``target``'s check), ``x`` itself or ``pointer(x)`` (:func:`pointee`) of
    an integer type of :data:`_CLOCK_INTS`; None for anything else (the table path)."""
    obj = target(p)
    tp = type(obj)
    if tp in _CLOCK_INTS:
        return obj
    ok = _CLOCK_POINTERS.get(tp)
    if ok is None:
        ok = _CLOCK_POINTERS[tp] = (
            issubclass(tp, ctypes._Pointer) and getattr(tp, "_type_", None) in _CLOCK_INTS
        )
    return pointee(p) if ok else None


def fast_clock(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """``GT_GetClock(pClock[, pLoop])`` with the fast path in front of the table: ``pClock``
    ``byref(x)``, ``x`` or ``pointer(x)`` of an integer type of at least 32 bits (or a ctypes
    or numpy array of one: its first element), ``pLoop`` omitted, None or 0, or (the
    vendor's two-pointer form) one of those scalar shapes taking the cycles run, on the
    in-process controller; anything else (a value the type cannot hold included) takes the
    table path."""
    from .args import _scalar_types
    from .table import FUNCTIONS

    target = _target(_CLOCK_INTS)
    first = _array_first(_scalar_types(FUNCTIONS[name].params[0]))

    def gt(pClock: Any = _NO, pLoop: Any = _NO, /, *extra: Any, **kw: Any) -> int:
        if (
            (
                pLoop is _NO
                or pLoop is None
                or (type(pLoop) is int and pLoop == 0)
                # the vendor's two-pointer form: the cycles run into pLoop too
                or (loop := clock_scalar(target, pLoop)) is not None
            )
            and not kw
            and not extra
        ):
            try:
                ctl = session.controllers[1]
            except KeyError:  # no controller: the table path says why
                ctl = None
            if ctl is not None and session.plain:  # (in this process, core 1)
                clock = ctl.clock
                if clock._thread is None:
                    tp = type(pClock)
                    q = pClock
                    if tp is _CArg:
                        obj = target(pClock)
                        if obj is pClock:  # byref(array[, offset]): its elements from there
                            q = array_at(pClock)
                            obj = None
                            tp = type(q)  # (None's: another byref, the table path)
                    elif tp in _CLOCK_INTS:
                        obj = pClock
                    else:
                        obj = clock_scalar(target, pClock)  # (pointer(x): x)
                    # GT_GetClock's own values (Controller.clock_ms, inline; the cycles run)
                    ms = ((clock.now_ns - ctl.reset_ns) // 1_000_000) & 0xFFFFFFFF
                    if pLoop is _NO or pLoop is None or type(pLoop) is int:
                        loop = None
                    else:
                        cycles = clock.cycles & 0xFFFFFFFF
                        if cycles > _INT_MAX[type(loop)]:  # (its bit pattern: the table)
                            obj = q = None
                            tp = type(None)
                    written = False
                    if obj is None:  # an array: its first element
                        b = first(q, tp)
                        if b is not None and ms <= b[1]:
                            q[0] = ms
                            written = True
                    elif ms <= _INT_MAX[type(obj)]:
                        obj.value = ms
                        written = True
                    if written:
                        if loop is not None:
                            loop.value = cycles
                        session.last = None
                        if clock.mode is _LOCKSTEP:
                            return 0
                        return advance(ctl, name, 0)
        return slow(*(a for a in (pClock, pLoop) if a is not _NO), *extra, **kw)

    gt.slow = slow  # type: ignore[attr-defined]  # the table path (tests compare both)

    def value() -> Any:
        """The C entry's value (asked while the GT_ gate is open: the in-process controller
        of core 1 on the lockstep or the auto clock): GT_GetClock's own."""
        ctl = GATED[0]
        ms = ((ctl.clock.now_ns - ctl.reset_ns) // 1_000_000) & 0xFFFFFFFF
        session.last = None
        return ms

    if not CENTRY:
        return gt
    types = CLOCK_ORDER
    # (an array of one of the types ``first`` takes: its first element)
    elements = [t for t in _scalar_types(FUNCTIONS[name].params[0]) if t._type_ in _INT_CODES]
    entry = centry.reader(
        gt, value, _NO, types, centry.INT, most=2, noaxis=True, gate=centry.GT_GATE,
        clocks=types,  # (pLoop's: byref(x), x or pointer(x), the cycles run written there)
        pointers=True,  # (pointer(x) too, as the Python path)
        after=_after(advance, name, 0),
        numpy=_int_dtypes(_scalar_types(FUNCTIONS[name].params[0])),  # (as ``first``)
        array=_first_element(lambda _: value(), elements),
        clock_of=vars(session),  # (the value in C where it has no last error to clear)
    )  # fmt: skip
    if entry is None:
        return gt
    entry.slow, entry.python = slow, gt
    return entry


#: GT_IsEcatReady, which a bring-up loop (and an HMI) polls
READY = "GT_IsEcatReady"


def fast_ready(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """``GT_IsEcatReady(pStatus)`` with its C entry in front of the table path: ``pStatus``
    ``byref(x)`` (no offset) or ``x`` of an integer type the pointer takes, on the in-process
    controller (the GT_ gate) whose bus is open and whose last GT_InitEcatComm did not fail;
    the status as the table path stores it.  Every other case (no bus, a failed bring-up
    and its reason): the table path."""
    from .args import _scalar_types
    from .table import FUNCTIONS

    def value() -> Any:
        ctl = GATED[0]
        if ctl.card is not None or ctl.init_error is not None:  # (the table says why)
            return _NO
        m = ctl.master
        if m is None or not m.opened:
            return _NO
        v = 1 if ctl.ready else 0
        session.last = None
        return v

    # (no Python fast function: the table path is the entry's ``python`` too)
    return _noaxis_entry(slow, value, _scalar_types(FUNCTIONS[name].params[0]), name, advance)  # type: ignore[no-any-return]


def wire_reader(name: str, long_size: int, session: Any) -> Callable[[Any], bytes | None]:
    """The same fast answer for a request that came over the controller socket
    (:mod:`gtecat.native.server`): ``body`` is the whole CALL message of ``name`` from a
    client whose ``long`` has ``long_size`` bytes; the reply frame, or None when the
    request is not the common shape (``count`` 1, ``pClock`` NULL, an axis that exists,
    a value that fits) and must take the table path.  One unpack, one pack: the request
    layout is the protocol's (CALL head, int64 axis, int32 size + the element, int64
    count, int32 size of pClock), the reply is one block holding the element."""
    from ..native.protocol import CALL, PTR_NULL
    from ._core import advance

    get, ctypes_ok = READERS[name]
    code = "d" if ctypes_ok is _DOUBLE else ("i" if long_size == 4 else "q")
    one = 8 if code != "i" else 4
    request = struct.Struct(f"<{CALL.format[1:]}qi{one}sqi")
    reply = struct.Struct(f"<IhHHI{code}")
    unpack, pack, size, total = request.unpack_from, reply.pack, request.size, reply.size - 4

    def answer(body: Any) -> bytes | None:
        if len(body) != size:
            return None
        axis, psize, _, count, pclock = unpack(body)[4:]
        ctl = session.controllers.get(1)  # the card the server selected for this call
        if psize != one or count != 1 or pclock != PTR_NULL or ctl is None:
            return None
        res = ctl.resources.get(axis)
        clock = ctl.clock
        if res is None or clock._thread is not None or session.remote is not None:
            return None
        try:
            out = pack(total, 0, 1, 0, one, get(res))
        except struct.error:  # a value the client's type cannot hold: the table decides
            return None
        session.last = None
        if clock.mode is not _LOCKSTEP and advance(ctl, name, 0) != 0:
            return None  # the cycle failed: the table path answers with the reason
        return out

    return answer


#: the raw image functions on the fast path (``offset, size, buffer``; the IO pair with the
#: slave first, offsets inside its region)
RAW = frozenset(
    {"GT_GetEcatRawData", "GT_SetEcatRawData", "GT_EcatIOReadInput", "GT_EcatIOWriteOutput"}
)
#: the raw functions that write into the process image
RAW_WRITES = frozenset({"GT_SetEcatRawData", "GT_EcatIOWriteOutput"})


def _raw_code(code: str, name: str) -> str:
    """A raw function's compiled code; a writer's makes the epoch grow where it has written
    (a reader's C entry asks again: :mod:`gtecat.controller.epoch`)."""
    if name not in RAW_WRITES:
        return code
    return re.sub(
        r"^( *)session\.last = None$",
        r"\1session.last = None\n\1EPOCH.n += 1",
        code,
        flags=re.M,
    )


_IO = frozenset({"GT_EcatIOReadInput", "GT_EcatIOWriteOutput"})
#: the ctypes objects a raw function copies into or out of (their memory, where it holds no
#: pointers: holds_pointers): arrays, simple types (``c_ushort``: a word of IO), structures
_CDATA = (ctypes.Array, ctypes._SimpleCData, ctypes.Structure, ctypes.Union)
#: their metatypes (byref_target: ``byref(x)`` of any of them)
_CDATA_METAS = [type(t) for t in _CDATA]
#: a memoryview's formats a raw function copies bytes into or out of: one native number type
#: (the table path reads them as numpy does; csrc/centry.c plain_format)
_PLAIN_FORMATS = frozenset(o + c for c in "bBhHiIlLqQfd?" for o in ("", "@", "=", "<", ">", "!"))
_CAST: Any = object()
_NUMPY: Any = object()
_BYTES_NP = np.dtype(np.uint8)


def _index(image: Any, offset: int, size: int, write: bool) -> np.ndarray | None:
    """The process-image indices of a raw range, or None when the fast path must not answer
    (outside the image, a masked or unaligned image, an input byte written: the table path
    gives the code and the reason)."""
    if offset < 0 or size <= 0 or offset + size > image.size or not image.aligned:
        return None
    if not image._full_bytes:
        return None
    if write and not image._raw_is_out[offset : offset + size].all():
        return None
    return image._raw_index[offset : offset + size].copy()


#: a raw range of at most this many runs of the image buffer is copied run by run
MAX_RUNS = 4
#: ... and by a shape's compiled copier (one struct call for all its runs)
COPY_RUNS = 64


def _plan(
    image: Any, offset: int, size: int, write: bool, max_runs: int = MAX_RUNS
) -> tuple[tuple[tuple[int, int, int], ...], np.ndarray] | None:
    """How a raw range is copied: its runs of the image buffer ``(first byte in the range,
    first byte in the buffer, bytes)`` (empty: too many, numpy copies it) and its buffer
    indices; None when the fast path must not answer (:func:`_index`)."""
    idx = _index(image, offset, size, write)
    if idx is None:
        return None
    cuts = np.flatnonzero(np.diff(idx) != 1) + 1
    starts = [0, *cuts.tolist()]
    ends = [*cuts.tolist(), size]
    if len(starts) > max_runs:
        return (), idx
    return tuple((a, int(idx[a]), b - a) for a, b in zip(starts, ends, strict=True)), idx


def fast_raw(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """``GT_GetEcatRawData`` / ``GT_SetEcatRawData`` (and the IO pair, slave first) with the
    fast path in front of the table: ``(int offset, int size, buffer)`` on the in-process
    controller with every slave online, the buffer a ctypes array, number or structure (a
    ``c_ushort`` for a word of IO; ``byref`` of one), a bytearray, a C-contiguous numpy array
    of numbers or memoryview of a plain number format (and for writes ``bytes`` too) holding
    at least ``size`` bytes: its memory's bytes, as the table path copies them.
    Into or from a bytearray, memoryview or bytes, a range of a few runs of the process image
    (a slave's outputs, its inputs) is copied run by run as slices; otherwise one numpy copy
    through a cached view; anything else takes the table path."""
    write = name in RAW_WRITES
    io = name in _IO
    cache: dict[tuple[int, int], tuple[int, np.ndarray] | None] = {}
    #: the image the cache is of and its bytes as a memoryview
    seen: list[Any] = [None, None]
    #: byte views of the caller's numpy buffers, the last few (kept alive)
    views: dict[tuple[int, int], tuple[Any, np.ndarray]] = {}
    copyto, frombuffer, u8 = np.copyto, np.frombuffer, np.uint8
    sizeof = ctypes.sizeof

    def view(p: Any, tp: type, size: int) -> np.ndarray | None:
        """``size`` bytes of the caller's buffer as a numpy array (None: not a fast shape)."""
        key = (id(p), size)
        v = views.get(key)
        if v is not None and v[0] is p:
            return v[1]
        if issubclass(tp, _CDATA):
            if sizeof(p) < size or holds_pointers(tp):  # (py_object, pointers: the table's 7)
                return None
            arr = frombuffer(p, u8, size)
        elif tp is _NDARRAY:
            if p.dtype.hasobject or not p.flags.c_contiguous or p.nbytes < size:
                return None
            if not write and not p.flags.writeable:
                return None
            arr = p.reshape(-1).view(u8)[:size]
        elif tp is bytearray or tp is memoryview or (write and tp is bytes):
            # never kept: a cached view would stop the caller resizing a bytearray
            if tp is memoryview and (p.format != "B" or p.ndim != 1 or not p.c_contiguous):
                return None
            if len(p) < size or (not write and tp is memoryview and p.readonly):
                return None
            return frombuffer(p, u8, size)
        else:
            return None
        if len(views) >= 16:
            views.clear()
        views[key] = (p, arr)
        return arr

    def copy_runs(p: Any, tp: type, runs: tuple, size: int) -> bool:
        """The runs of the image to or from the caller's buffer (False: not this way)."""
        img = seen[1]
        if tp is bytearray or tp is memoryview or (tp is bytes and write):
            if len(p) < size:
                return False
            if tp is memoryview:
                if p.format != "B" or p.ndim != 1 or not p.c_contiguous:
                    return False
                if p.readonly and not write:
                    return False
            if write:
                for a, first, n in runs:
                    img[first : first + n] = p[a : a + n]
            else:
                for a, first, n in runs:
                    p[a : a + n] = img[first : first + n]
            return True
        return False  # ctypes and numpy buffers: one numpy copy through a cached view

    def range_plan(slave: int, offset: int, size: int, image: Any) -> Any:
        """The image buffer's plan of a raw range (:func:`_plan`; a slave's region where
        ``io``: ``slave`` >= 0, the range within its inputs or outputs), or None where the
        range is not one the fast paths copy (the general path says why)."""
        raw = offset
        if io:
            slaves = image.layout.slaves
            if not 0 <= slave < len(slaves):
                return None
            sl = slaves[slave]
            if offset < 0 or offset + size > (sl.out_bytes if write else sl.gt_size):
                return None
            raw = sl.gt_offset + offset
        plan = _plan(image, raw, size, write, COPY_RUNS)
        return None if plan is None or not plan[0] else plan

    #: (slave or -1, offset, size, the buffer's type) -> a copier: ``copy(p)`` moves the
    #: bytes (False: this buffer cannot take them this way, the general path decides)
    copiers: dict[tuple[int, int, int, type], Callable[[Any], bool]] = {}

    def copier(slave: int, offset: int, size: int, tp: type, image: Any) -> Any:
        """``copy(p)`` for one shape (a range of the image, a buffer type): it moves the
        bytes and returns True, or False when this buffer cannot take them this way (the
        general path decides); None: no copier for the shape.  Compiled from the range's
        runs of the image buffer: each run is a ``c_char`` array over its bytes of the
        image, and one ``struct`` call moves them all into or out of the caller's buffer
        (``pack_into`` / ``unpack_from`` check that the buffer is big enough, writable for
        a read, and C-contiguous; whatever they refuse goes to the general path)."""
        plan = range_plan(slave, offset, size, image)
        if plan is None:
            return None
        runs = plan[0]
        if tp is bytearray or (write and tp is bytes):
            ok = []
        elif tp is memoryview:  # (numbers: pack_into / unpack_from check the rest)
            ok = ["p.format in _PLAIN_FORMATS"]
        elif issubclass(tp, _CDATA) and sizeof(tp) >= size and not holds_pointers(tp):
            ok = []  # (pointers or py_object are not raw memory: the table's 7)
        elif tp is _NDARRAY:  # (any numbers: pack_into / unpack_from check the rest)
            ok = ["not p.dtype.hasobject"]
        else:
            return None
        check = [f"if not ({' and '.join(ok)}): return False"] if ok else []
        fmt = struct.Struct("".join(f"{n}s" for _, _, n in runs))
        env: dict[str, Any] = {"_BYTES_NP": _BYTES_NP, "_PLAIN_FORMATS": _PLAIN_FORMATS}
        cells = []
        for k, (_, first, n) in enumerate(runs):
            env[f"c{k}"] = (ctypes.c_char * n).from_buffer(image.buffer, first)
            cells.append(f"c{k}.raw")
        if write:
            env["unpack"] = fmt.unpack_from
            move = [f"{', '.join(cells)}, = unpack(p)"]
        else:
            env["pack"] = fmt.pack_into
            move = [f"pack(p, 0, {', '.join(cells)})"]
        body = "\n    ".join([*check, *move, "return True"])
        exec(_compiled_code(f"def copy(p):\n    {body}\n", f"<gt copy {name}>"), env)
        copy = env["copy"]
        names = {k: v for k, v in env.items() if k != "copy" and not k.startswith("__")}
        copy.spec = (ok, move[0], names)  # (for the specialised entry, _raw_entry)
        return copy

    def reset(image: Any) -> None:
        """Another process image (the bus was brought up again): every copier goes."""
        cache.clear()
        copiers.clear()
        seen[:] = [image, memoryview(image.buffer)]
        remember(-1, -1, None, -1, None, False)
        entries.clear()
        entry.__code__ = base_code

    def remember(offset: int, size: int, tp: Any, slave: int, copy: Any, ref: bool) -> None:
        """The shape the next call is checked against first, and its copier; the public
        function becomes the entry specialised for it (:data:`_RAW_ENTRY`; ``ref``: the
        buffer came as ``byref(array)``, which that entry then takes too)."""
        env["LAST"] = (offset, size, tp, slave, copy, ref)
        if copy is None:
            return
        key = (slave, offset, size, tp, ref)
        code = entries.get(key)
        if code is None:
            code = entries[key] = _raw_entry(env, io, len(entries), key, seen[0], copy.spec)
        entry.__code__ = code

    #: (slave, offset, size, buffer type) -> the code of the public function specialised
    #: for that shape (the copy inline, behind the checks of the shape and the session)
    entries: dict[tuple, Any] = {}

    env = {
        "ARRAY_TARGET": byref_target.target(_CDATA_METAS) if BYREF_TARGET else None,
        "LAST": (-1, -1, None, -1, None, False),
        "_NO": _NO,
        "_LOCKSTEP": _LOCKSTEP,
        "session": session,
        "seen": seen,
        "copiers": copiers,
        "copier": copier,
        "reset": reset,
        "remember": remember,
        "advance": advance,
        "name": name,
        "slow": slow,
    }
    gt = _compiled_raw(env, io)
    env["generic"] = gt
    env["run"] = lambda *a: run(*a)
    # the public function: until a shape is seen, the generic one; then specialised
    entry = _raw_entry(env, io, -1, None, None, None)
    base_code = entry.__code__

    def run(slave: int, offset: Any, size: Any, p: Any, args: tuple) -> int:
        ctl = session.controllers.get(1)
        m = ctl.master if ctl is not None else None
        if (
            type(offset) is not int
            or type(size) is not int
            or m is None
            or not m.opened
            or m.offline
            or session.remote is not None
            or ctl.clock._thread is not None
            or session.core != 1  # GT_SetCore: another core
        ):
            return slow(*args)
        image = m.image
        raw = offset
        if io:  # an offset inside one slave's region (the table path's _region)
            slaves = image.layout.slaves
            if not 0 <= slave < len(slaves):
                return slow(*args)
            sl = slaves[slave]
            if offset < 0 or offset + size > (sl.out_bytes if write else sl.gt_size):
                return slow(*args)
            raw = sl.gt_offset + offset
        if image is not seen[0]:
            cache.clear()
            seen[0], seen[1] = image, memoryview(image.buffer)
        key = (raw, size)
        plan = cache.get(key, _NO)
        if plan is _NO:
            plan = cache[key] = _plan(image, raw, size, write)
        if plan is None:
            return slow(*args)
        runs, idx = plan
        tp = type(p)
        try:
            done = bool(runs) and copy_runs(p, tp, runs, size)
            arr = None if done else view(p, tp, size)
        except ValueError:  # (a released memoryview): the table path gives 7 and why
            return slow(*args)
        if not done:
            if arr is None:
                return slow(*args)
            if write:
                image.buffer[idx] = arr
            else:
                copyto(arr, image.buffer.take(idx))  # (np.take with out= costs microseconds)
        session.last = None
        if write:
            EPOCH.n += 1  # (the readers' C entries ask again: epoch.py)
        if ctl.clock.mode is not _LOCKSTEP:
            return advance(ctl, name, 0)
        return 0

    entry.slow = slow  # type: ignore[attr-defined]
    entry.generic = gt  # type: ignore[attr-defined]
    if not CENTRY:
        return entry
    #: the C entry's copies: (slave, offset, size) -> the range's runs of the image's buffer
    #: (centry.runs), or None; kept for the image named first
    addresses: dict[tuple[int, int, int], int | None] = {}
    addressed: list[Any] = [None]
    #: an array type -> its size where the C entry copies into or out of it (0: it holds
    #: pointers, the table path's 7); a bytearray's (and bytes', to write from) the C entry
    #: checks itself
    array_sizes: dict[type, int] = {bytearray: 1 << 62, bytes: 1 << 62 if write else 0}
    array_sizes |= {memoryview: 1 << 62, _NDARRAY: 1 << 62}  # (checked in C too)

    def address(slave: int, offset: int, size: int, image: Any) -> bytes | None:
        """Where a raw range (a slave's region: ``slave`` >= 0) lies in the image's buffer:
        its runs (:func:`centry.runs`), where the fast path copies it; else None."""
        plan = range_plan(slave, offset, size, image)
        if plan is None:
            return None
        base = int(image.buffer.ctypes.data)
        return centry.runs((a, base + first, n) for a, first, n in plan[0])

    def runs_of(slave: int, offset: int, size: int, tp: type, image: Any) -> Any:
        """The C entry's runs of a shape (its array type big enough, the range copied by
        the fast path), else _NO; the shape remembered for the next call (``LASTC``)."""
        n = array_sizes.get(tp)
        if n is None:
            n = array_sizes[tp] = 0 if holds_pointers(tp) else sizeof(tp)
        if n < size:
            return _NO
        if image is not addressed[0]:
            addresses.clear()
            addressed[0] = image
        key = (slave, offset, size)
        at = addresses.get(key, _NO)
        if at is _NO:
            at = addresses[key] = address(slave, offset, size, image)
        if at is None:
            return _NO
        venv["LASTC"] = (offset, size, tp, image, slave, at)
        session.last = None  # (a write: the C entry makes the epoch grow where it changed)
        return at

    venv = {
        "_NO": _NO,
        "_LOCKSTEP": _LOCKSTEP,
        "session": session,
        "runs_of": runs_of,
        "LASTC": (None, None, None, None, None, None),
    }
    code = _RAW_VALUE.format(
        slave="slave, " if io else "",
        slave_key="slave" if io else "-1",
        slave_memo=" and slave == last[4]" if io else "",
    )
    _gated(venv)
    # (a write's value does not make the epoch grow: its C entry does, where the write
    # changed a byte of the image - centry.raw's changed)
    exec(_compiled_code(code, f"<gt raw value {name}>"), venv)
    value = venv["value"]

    public = centry.raw(
        entry, value, _NO, io, write, centry.GT_GATE, _after(advance, name, 0), changed
    )
    if public is None:
        return entry
    public.slow, public.generic, public.python = slow, gt, entry
    return public


#: GT_EcatIOBitWriteOutput, which an application that drives single outputs calls every cycle
BIT_WRITE = "GT_EcatIOBitWriteOutput"


def fast_bit_write(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """``GT_EcatIOBitWriteOutput(slave, offset, bit, value)`` with the fast path in front of
    the table: plain ints, ``bit`` 0..7 and ``value`` 0 or 1 (the table's ranges), on the
    in-process controller of core 1 with every slave online, an output byte of the slave's
    region (:func:`fast_raw`'s conditions for a write): the bit is set or cleared in that
    byte of the process image directly, as GT_EcatIOWriteOutput's fast path writes its bytes
    (the readers' epoch grows where the byte changed); anything else takes the table path,
    which says why."""
    #: (slave, offset) -> a c_ubyte over its output byte of the image (None: the table's)
    cells: dict[tuple[int, int], Any] = {}
    #: the image the cells are of, and the latest call's (slave, offset, cell)
    memo: list[Any] = [None, -1, -1, None]

    def cell(image: Any, slave: int, offset: int) -> Any:
        if image is not memo[0]:
            cells.clear()
            memo[0] = image
        c = cells.get((slave, offset), _NO)
        if c is _NO:
            c = None
            slaves = image.layout.slaves
            if 0 <= slave < len(slaves) and 0 <= offset < slaves[slave].out_bytes:
                plan = _plan(image, slaves[slave].gt_offset + offset, 1, True)
                if plan is not None and plan[0]:
                    c = ctypes.c_ubyte.from_buffer(image.buffer, plan[0][0][1])
            if len(cells) >= 256:
                cells.clear()
            cells[(slave, offset)] = c
        memo[1:] = slave, offset, c
        return c

    def gt(
        slave: Any = _NO, offset: Any = _NO, bit: Any = _NO, value: Any = _NO, /, *extra: Any,
        **kw: Any,
    ) -> int:  # fmt: skip
        if (
            type(bit) is int
            and 0 <= bit <= 7
            and (value == 0 or value == 1)
            and type(value) is int
            and type(slave) is int
            and type(offset) is int
            and not extra
            and not kw
            and session.plain  # (in this process, core 1)
        ):
            ctl = session.controllers.get(1)
            if ctl is not None:
                m = ctl.master
                clock = ctl.clock
                if m is not None and m.opened and not m.offline and clock._thread is None:
                    image = m.image
                    if slave == memo[1] and offset == memo[2] and image is memo[0]:
                        c = memo[3]
                    else:
                        c = cell(image, slave, offset)
                    if c is not None:
                        old = c.value
                        new = (old | (1 << bit)) if value else (old & ~(1 << bit))
                        if new != old:
                            c.value = new
                            EPOCH.n += 1  # (the readers' C entries ask again: epoch.py)
                        session.last = None
                        if clock.mode is _LOCKSTEP:
                            return 0
                        return advance(ctl, name, 0)
        return slow(*(a for a in (slave, offset, bit, value) if a is not _NO), *extra, **kw)

    gt.slow = slow  # type: ignore[attr-defined]
    if not CENTRY:
        return gt
    #: the C entry's runs of an output byte: (slave, offset) -> its run (centry.runs), or None
    addresses: dict[tuple[int, int], bytes | None] = {}
    addressed: list[Any] = [None]

    def runs_of(slave: int, offset: int, image: Any) -> Any:
        if image is not addressed[0]:
            addresses.clear()
            addressed[0] = image
        at = addresses.get((slave, offset), _NO)
        if at is _NO:
            c = cell(image, slave, offset)
            at = None if c is None else centry.runs([(0, ctypes.addressof(c), 1)])
            if len(addresses) >= 256:
                addresses.clear()
            addresses[(slave, offset)] = at
        if at is None:
            return _NO
        session.last = None  # (the C entry makes the epoch grow where the byte changed)
        return at

    venv: dict[str, Any] = {"_NO": _NO, "session": session, "runs_of": runs_of}
    _gated(venv)
    # (asked while the GT_ gate is open: CTL the in-process controller of core 1; the bit
    # and the value the C entry checked, the byte's runs kept for their epoch)
    exec(
        _compiled_code(
            "def value(slave, offset, bit, tp):\n"
            "    m = CTL.master\n"
            "    if m is not None and m.opened and not m.offline:\n"
            "        return runs_of(slave, offset, m.image)\n"
            "    return _NO\n",
            f"<gt bit value {name}>",
        ),
        venv,
    )
    public = centry.raw(
        gt, venv["value"], _NO, True, centry.BIT_WRITE, centry.GT_GATE, _after(advance, name, 0),
        changed,
    )  # fmt: skip
    if public is None:
        return gt
    public.slow, public.python = slow, gt
    return public


#: the public raw function specialised for the shape of the latest call (a polling loop
#: repeats its shape): that shape's checks, the session's, and its copy inline; any other
#: call: the generic function (which specialises it again for its own shape)
_RAW_ENTRY = """
def gt({slave}offset=_NO, size=_NO, p=_NO, /, *extra, **kw):{unwrap}
    if (
        type(p) is T{n}
        and offset == {offset}
        and size == {size}
        and type(offset) is int
        and type(size) is int{slave_guard}
        and not extra
        and not kw
    ):
        try:
            ctl = session.controllers[1]
        except KeyError:  # no controller: the generic path says why
            return generic({slave_arg}offset, size, {given})
        m = ctl.master
        clock = ctl.clock
        if (
            session.plain  # (in this process, core 1)
            and m is not None
            and m.image is IMG{n}
            and m.opened
            and not m.offline
            and clock._thread is None
        ):
            try:{ok}
                {move}
            except Exception:  # (the buffer's own refusal): the generic path answers
                pass
            else:
                session.last = None
                if clock.mode is _LOCKSTEP:
                    return 0
                return advance(ctl, name, 0)
    return generic({slave_arg}offset, size, {given}, *extra, **kw)
"""


#: a raw function's value for its C entry (centry.raw): the session's checks, then the runs
#: of the previous call's shape (a polling loop repeats its shape), else runs_of's
#: (asked while the GT_ gate is open: CTL the in-process lockstep controller)
_RAW_VALUE = """
def value({slave}offset, size, tp):
    m = CTL.master
    if m is not None and m.opened and not m.offline:
        last = LASTC  # (one read: another thread may replace it meanwhile)
        if (
            offset == last[0]
            and size == last[1]
            and tp is last[2]
            and m.image is last[3]{slave_memo}
        ):
            session.last = None
            return last[5]
        return runs_of({slave_key}, offset, size, tp, m.image)
    return _NO
"""


class _NotThis(Exception):
    """(A specialised raw entry's buffer is not of its shape: the generic path answers.)"""


#: the front of an entry specialised for ``byref(array)``: the array itself, the rest as for it
_RAW_UNWRAP = """
    given = p  # (what the generic path gets, if it answers)
    if type(p) is _CArg:
        q = p._obj
        if type(q) is T{n} and {address} == _addressof(q):
            p = q"""
#: the same with the check in one C call (ARRAY_TARGET: an array that p points at, else p)
_RAW_UNWRAP_C = """
    given = p  # (what the generic path gets, if it answers)
    if type(p) is _CArg:
        q = ARRAY_TARGET(p)
        if type(q) is T{n}:
            p = q"""

_RAW_BASE = """
def gt({slave}offset=_NO, size=_NO, p=_NO, /, *extra, **kw):
    return generic({slave_arg}offset, size, p, *extra, **kw)
"""


def _raw_entry(env: dict[str, Any], io: bool, n: int, key: Any, image: Any, spec: Any) -> Any:
    """The public function (``n`` -1: the generic one's front) or, for shape ``key`` of
    ``image`` with its copier's ``spec``, the code of its specialised entry; the names it
    uses go into ``env`` (its globals) with the suffix ``n``."""
    fmt = {"slave": "slave=_NO, " if io else "", "slave_arg": "slave, " if io else ""}
    if n < 0:
        exec(_compiled_code(_RAW_BASE.format(**fmt), f"<gt fast raw {env['name']}>"), env)
        return env.pop("gt")
    slave, offset, size, tp, ref = key
    ok, move, names = spec
    for k, v in names.items():
        move = re.sub(rf"\b{k}\b", f"{k}_{n}", move)
        ok = [re.sub(rf"\b{k}\b", f"{k}_{n}", x) for x in ok]
        env[f"{k}_{n}"] = v
    env[f"T{n}"], env[f"IMG{n}"] = tp, image
    env["_NotThis"] = _NotThis
    code = _RAW_ENTRY.format(
        **fmt,
        n=n,
        offset=offset,
        size=size,
        slave_guard=f"\n        and slave == {slave}\n        and type(slave) is int" if io else "",
        # (inside the try: a released memoryview raises at its first attribute)
        ok=f"\n                if not ({' and '.join(ok)}): raise _NotThis" if ok else "",
        move=move,
        unwrap=(
            ""
            if not ref
            else _RAW_UNWRAP_C.format(n=n)
            if env.get("ARRAY_TARGET") is not None
            else _RAW_UNWRAP.format(n=n, address=carg_address_source("p"))
        ),
        given="given" if ref else "p",
    )
    scratch: dict[str, Any] = {}
    env["EPOCH"] = EPOCH
    code = _raw_code(code, env["name"])
    exec(_compiled_code(code, f"<gt fast raw {env['name']} shape {n}>"), env, scratch)
    return scratch["gt"].__code__


#: the raw image functions' common shapes in the fewest steps (the IO pair with the slave
#: first): the session's checks, then the shape's copier; anything else: ``run``
_RAW = """
def gt({slave}offset=_NO, size=_NO, p=_NO, /, *extra, **kw):
    if extra or kw or p is _NO{slave_check}:
        return slow(*(a for a in ({slave_arg}offset, size, p) if a is not _NO), *extra, **kw)
    given = p  # (what the table path gets, if it answers)
    ref = type(p) is _CArg
    if ref:
        # byref(array): the array itself (byref(array, offset), byref of anything else: the
        # table path)
{unwrap}
    ctl = session.controllers.get(1)
    if (
        ctl is not None
        and type(offset) is int
        and type(size) is int
        and session.plain  # (in this process, core 1)
    ):
        m = ctl.master
        clock = ctl.clock
        if m is not None and m.opened and not m.offline and clock._thread is None:
            image = m.image
            if image is not seen[0]:
                reset(image)
            tp = type(p)
            # the shape of the previous call (a polling loop repeats its shape), else the
            # copiers by shape
            last = LAST  # (one read: another thread may replace it meanwhile)
            if (
                offset == last[0]
                and size == last[1]
                and tp is last[2]
                and ref is last[5]{slave_memo}
            ):
                copy = last[4]
            else:
                key = ({slave_key}, offset, size, tp)
                copy = copiers.get(key, _NO)
                if copy is _NO:
                    copy = copiers[key] = copier({slave_key}, offset, size, tp, image)
                remember(offset, size, tp, {slave_key}, copy, ref)
            if copy is None:
                done = False
            else:
                try:
                    done = copy(p)
                except Exception:  # (a released memoryview): the general path answers
                    done = False
            if done:
                session.last = None
                if clock.mode is _LOCKSTEP:
                    return 0
                return advance(ctl, name, 0)
    return run({slave_key}, offset, size, p, ({slave_arg}offset, size, given))
"""


def _compiled_raw(env: dict[str, Any], io: bool) -> Any:
    code = _RAW.format(
        slave="slave=_NO, " if io else "",
        slave_check=" or type(slave) is not int" if io else "",
        slave_arg="slave, " if io else "",
        slave_key="slave" if io else "-1",
        slave_memo=" and slave == last[3]" if io else "",
        unwrap=(
            "        p = ARRAY_TARGET(p)  # (one C call: the array, else p itself)"
            if env.get("ARRAY_TARGET") is not None
            else "        q = p._obj\n"
            "        if isinstance(q, _CDATA) and {address} == _addressof(q):\n"
            "            p = q"
        ),
    )
    code = code.replace("{address}", carg_address_source("p"))
    env.update(CARG_ENV)
    env.update(_CArg=_CArg, _CDATA=_CDATA, _addressof=_addressof, EPOCH=EPOCH)
    code = _raw_code(code, env["name"])
    exec(_compiled_code(code, f"<gt fast raw {env['name']}>"), env)  # env: its globals
    return env["gt"]


#: why a function that takes pointers is answered by the table path only (its binder checks
#: and converts every argument generically: a few microseconds).  By group; every function of
#: the table with a pointer parameter is on the fast path (READERS, RAW), declared only, or
#: covered here (tests/gtecat/gt/test_fast_shapes.py walks the table).
SLOW_REASONS: dict[str, str] = {
    "buffered": "buffered commands: each call queues planning work that outweighs its arguments",
    "compare": "position compare and trigger set-up, data and status: table path",
    "crd_ex": "extended coordinated-motion queue calls: the planning work outweighs the arguments",
    "lead_screw": "lead-screw compensation tables: set up once",
    "legacy_home": "the older homing calls: set up once; GT_HomeSts, which a homing loop "
    "polls, is on the fast path (gtecat.gt.fast_legacy_home)",
    "look_ahead_ex": "look-ahead set-up and planner modes: set up once",
    "net_init": "network cards' set-up and their encoder readers: table path",
    "pvt": "PVT tables and status: the table work outweighs the arguments",
    "bus": "bus set-up, identity and SDO calls (an SDO transfer costs far more than its "
    "arguments); the clock and version readers are answered after the table's checks",
    "crd": "coordinated-motion set-up and queue calls: the planning work outweighs the "
    "arguments; GT_CrdStatus, which a loop polls, has a C entry (MULTI_READERS)",
    "ecat_axis": "probe status, the axis mode, analog inputs and the scale: table path; the "
    "per-axis PDO readers and the homing status that polling loops use are on the fast path",
    "ecat_io": "one output bit read: table path",
    "emulator": "emulator helpers for tests, not called in control loops",
    "ext_io": "extension-module IO: each call walks the module configuration (table path)",
    "gantry": "a mode query: table path",
    "gts_card": "the pulse-card (GTS) set-up, capture and smart-homing calls: table path; the "
    "polled IO readers (GT_GetDi, GT_GetDiRaw, GT_GetDo) are on the fast path, and "
    "GT_GetCaptureStatus has a C entry (MULTI_READERS)",
    "motion": "profile set-up and parameter readers (called once per move); the position and "
    "speed readers that polling loops use, and GT_GetTrapPrm, are on the fast path",
    "plcopen": "PLCopen function blocks: each call plans or reads a block's state (table path)",
    "programs": "motion programs, variables and MRAM: compile and download work outweighs "
    "the arguments",
    "pt_gear_follow": "PT/gear/follow queue and set-up readers: table path",
    "servo_loop": "servo-loop parameters, analog values and the inputs' change counters "
    "(GT_GetDiReverseCount: a span of counters, read through the kept input readers): table "
    "path",
    "status": "status set-up readers (soft limits, bands, stop decelerations) and the "
    "configuration file: GT_GetSts, the polled one, is on the fast path",
}


#: a client's shapes of a fast function's value pointer that the table path answers, and why
#: (tests/gtecat/gt/test_fast_walk.py walks every fast function's shapes and fails on any
#: other that reaches the table)
SLOW_SHAPES: dict[str, dict[str, str]] = {}
#: What the fast path leaves to the table on purpose besides those: a call the table refuses
#: (code 7 and its reason: ``array.array``, which is not a pointer argument; a strided numpy
#: view; a ``c_double`` where the prototype says ``long *``; a read-only buffer to read into)
#: is answered by the table path, whose binder finds which argument is wrong and words the
#: reason (a few microseconds).  A refused call changes nothing and a program does not poll
#: it, so its cost is not held to its arguments'; every shape a call succeeds with is.
#: (filled below for the functions it names, once they are all declared)
_VIEW_REASON = (
    "a memoryview of the value's array: the axis readers (READERS) answer it as the array "
    "itself; this function's fast path takes the array, byref of it, the object or a numpy "
    "array, and the table path answers the view (a few microseconds)"
)


def fast_functions() -> frozenset[str]:
    """The functions whose common shapes the fast path answers."""
    return (
        frozenset(READERS)
        | RAW
        | {CLOCK, CORE, HOMING}
        | frozenset(IO_READERS)
        | frozenset(ECAT_READERS)
        | frozenset(STRUCT_READERS)
    )


#: the per-axis PDO readers (axis_calls._reader): function -> the object it reads
ECAT_READERS: dict[str, tuple[int, int]] = {
    "GT_GetEcatEncPos": (0x6064, 0),
    "GT_GetEcatEncVel": (0x606C, 0),
    "GT_GetEcatAxisPE": (0x60F4, 0),
    "GT_GetEcatAxisDI": (0x60FD, 0),
    "GT_GetEcatAxisDO": (0x60FE, 1),
    "GT_GetEcatAxisAtITorque": (0x6077, 0),
    "GT_GetEcatAxisAtICurrent": (0x6078, 0),
    "GT_GetEcatErrorCode": (0x603F, 0),
}


def _pdo_entry(ax: Any, acc: Any, bounds: dict[type, tuple[int, int]]) -> tuple[Any, ...]:
    """A PDO reader's entry of one axis: ``(axis, accessor, cell, fits)``: ``cell`` the
    entry's bytes of the process image as a one-item memoryview of its integer type (what
    the accessor's ``get`` reads for a whole-byte entry, read by one index), None where the
    accessor reads bits or the machine is big-endian (its ``get`` then); ``fits`` the
    pointer types that hold every value of the entry (no range check needed)."""
    if acc is None:
        return ax, None, None, frozenset()
    lo, hi = (
        (-(1 << (acc.bits - 1)), (1 << (acc.bits - 1)) - 1)
        if acc.signed
        else (0, (1 << acc.bits) - 1)
    )
    fits = frozenset(t for t, (a, b) in bounds.items() if a <= lo and hi <= b)
    fmt = getattr(acc, "_fmt", None)
    buf = getattr(acc, "_buf", None)
    cell = None
    if fmt is not None and sys.byteorder == "little" and isinstance(buf, memoryview):
        code = fmt.format[-1]  # ("<i": little-endian, standard sizes)
        size = fmt.size
        try:
            view = buf[acc._off : acc._off + size].cast("B").cast(code)
        except (TypeError, ValueError):
            view = None
        if view is not None and view.itemsize == size and len(view) == 1:
            cell = view
    return ax, acc, cell, fits


def fast_ecat_reader(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """``GT_GetEcatEncPos(axis, p)`` and the other per-axis PDO readers with the fast path in
    front of the table: ``p`` a ``byref`` (no offset) or the object itself of a number type
    the pointer takes, holding the value; the axis on the in-process controller's bus (no
    pulse card), its link up, the object mapped.  An axis the axis bank runs is read where
    it is, past its guard (the table path would give it back, and the bank claim it again at
    its next cycle): the bank writes its drives' TxPDO into the image every cycle it runs
    them, and their other entries do not change while it does.  Anything else (an error
    included) takes the table path, which gives the code and the reason."""
    from ..controller.axis import Axis
    from .args import _scalar_types
    from .table import FUNCTIONS

    index, subindex = ECAT_READERS[name]
    param = FUNCTIONS[name].params[1]
    ok = _scalar_types(param)
    bounds = {}
    for t in ok:
        bits = 8 * ctypes.sizeof(t)
        bounds[t] = (
            (0, (1 << bits) - 1)
            if t._type_.isupper()
            else (-(1 << (bits - 1)), (1 << (bits - 1)) - 1)
        )
    env = {
        "_NO": _NO,
        "_CArg": _CArg,
        "_LOCKSTEP": _LOCKSTEP,
        "_addressof": _addressof,
        "_AXIS": Axis,
        "_get": object.__getattribute__,
        "session": session,
        "advance": advance,
        "name": name,
        "slow": slow,
        "ok": ok,
        "BOUNDS": bounds,
        "INDEX": index,
        "SUB": subindex,
        "ACCS": {},
        "_pdo_entry": _pdo_entry,
        "first": _array_first(ok),
        "array_at": array_at,
        "last": [None],
        "_refs": sys.getrefcount,
        "KEPT": _KEPT,
    }
    target = byref_target.target(ok) if BYREF_TARGET else None
    if target is not None:
        env["TARGET"] = target
        byref = _ECAT_BYREF_C
    else:
        byref = _ECAT_BYREF_PY.replace("{address}", carg_address_source("p"))
    env.update(CARG_ENV)
    code = _ECAT_READER.replace("{byref}", byref)
    exec(_compiled_code(code, f"<gt fast ecat {name}>"), env)
    gt = env["gt"]
    gt.slow = slow
    _gated(env)
    _CACHES.append(env["ACCS"])  # (axis -> its entry: a controller's axes)
    exec(_compiled_code(_ECAT_VALUE, f"<gt ecat {name}>"), env)
    return _entry(  # type: ignore[no-any-return]
        gt, env["value"], ok, centry.INT, gate=centry.GT_GATE, after=_after(advance, name, 0)
    )


#: a PDO reader's value for its C entry (the common case of ``_ECAT_READER``, the axis's
#: entry kept by it); else _NO
#: (asked while the GT_ gate is open: CTL the in-process lockstep controller)
_ECAT_VALUE = """
def value(n):
    ctl = CTL
    try:
        ax = ctl.axes[n]
    except KeyError:  # no such axis
        return _NO
    m = ctl.master
    if (
        m is not None
        and m.opened
        and ctl.card is None
        and not (ax.link_lost if type(ax) is _AXIS else _get(ax, "link_lost"))
    ):
        kept = ACCS.get(n)
        if kept is not None and kept[0] is ax and kept[1] is not None:
            cell = kept[2]
            v = kept[1].get() if cell is None else cell[0]
            session.last = None
            return v
    return _NO
"""


#: the byref branch of a PDO reader: one C call (see _BYREF_C) ...
_ECAT_BYREF_C = """\
                    obj = TARGET(p)
                    if obj is p:  # byref(array[, offset]): its elements from there
                        q = array_at(p)
                        b = None if q is None else first(q, type(q))
                        if b is None:  # (byref(x, offset), another type: the table path)
                            return slow(n, p)
                        obj = None"""
#: ... else read from Python
_ECAT_BYREF_PY = """\
                    obj = p._obj
                    if p is not last[0]:
                        if type(obj) not in ok or {address} != _addressof(obj):
                            return slow(n, p)  # (p is a byref here)
                        if _refs(p) > KEPT:  # (kept by the caller: see _KEPT)
                            last[0] = p"""

_ECAT_READER = """
def gt(n=_NO, p=_NO, /, *extra, **kw):
    if type(n) is int and not kw and not extra:
        try:
            ctl = session.controllers[1]
            ax = ctl.axes[n]
        except KeyError:  # no controller, or no such axis: the table path says why
            return slow(*(a for a in (n, p) if a is not _NO))
        clock = ctl.clock
        m = ctl.master
        if (
            session.plain  # (in this process, core 1)
            and clock._thread is None
            and m is not None
            and m.opened
            and ctl.card is None
            # (an axis the bank runs is read past its guard, which would give it back: the
            # bank writes its drives' TxPDO into the image every cycle it runs them)
            and not (ax.link_lost if type(ax) is _AXIS else _get(ax, "link_lost"))
        ):
            kept = ACCS.get(n)  # (the axis's entry, kept: AxisIo.get keeps it too)
            if kept is None or kept[0] is not ax:
                if len(ACCS) > 4096:
                    ACCS.clear()
                io = ax.io if type(ax) is _AXIS else _get(ax, "io")
                kept = ACCS[n] = _pdo_entry(ax, io.get(INDEX, SUB), BOUNDS)
            _, acc, cell, fits = kept  # (acc None: not mapped; the table path says so)
            if acc is not None:
                tp = type(p)
                q = p
                if tp is _CArg:
{byref}
                elif tp in ok:
                    obj = p
                else:
                    b = first(p, tp)  # (an array: its first element)
                    if b is None:
                        return slow(*(a for a in (n, p) if a is not _NO))
                    obj = None
                v = acc.get() if cell is None else cell[0]
                # (a value the type cannot hold: store's refusal, the table path)
                if obj is None:
                    done = b[0] <= v <= b[1]
                    if done:
                        q[0] = v
                else:
                    kind = type(obj)
                    done = kind in fits or BOUNDS[kind][0] <= v <= BOUNDS[kind][1]
                    if done:
                        obj.value = v
                if done:
                    session.last = None
                    if clock.mode is _LOCKSTEP:
                        return 0
                    return advance(ctl, name, 0)
    return slow(*(a for a in (n, p) if a is not _NO), *extra, **kw)
"""


#: the homing status reader on the fast path (the vendor's homing loop polls it)
HOMING = "GT_GetEcatHomingStatus"


def status_reader(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
    status: Callable[[int], tuple[Any, int] | None],
    ok: Any,
) -> Callable[..., int]:
    """``f(axis, p)`` of a reader of one integer answered from ``status(axis)`` ((the
    controller, the value), or None: the table path): ``p`` a ``byref`` (no offset) or the
    object itself of an integer type of ``ok``, or an array of one (its first element); a
    value the type does not hold and any other shape: the table path (``slow``), with its
    code and reason.  The homing status readers' shared front (GT_GetEcatHomingStatus,
    the older cards' GT_HomeSts)."""
    bounds, target, first = _int_bounds(ok), _target(ok), _array_first(ok)

    def gt(n: Any = _NO, p: Any = _NO, /, *extra: Any, **kw: Any) -> int:
        if type(n) is int and not kw and not extra:
            obj, arr = _value_target(p, target, ok, first)
            if obj is not None:
                got = status(n)
                if got is not None:
                    ctl, v = got
                    lo, hi = bounds[type(obj)] if arr is None else arr
                    if lo <= v <= hi:
                        if arr is None:
                            obj.value = v
                        else:
                            obj[0] = v
                        session.last = None
                        if ctl.clock.mode is _LOCKSTEP:
                            return 0
                        return advance(ctl, name, 0)
        return slow(*(a for a in (n, p) if a is not _NO), *extra, **kw)

    gt.slow = slow  # type: ignore[attr-defined]
    return gt


def fast_homing_status(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """``GT_GetEcatHomingStatus(axis, p)`` with the fast path in front of the table: ``p`` a
    ``byref`` (no offset) or the object itself of an integer type the pointer takes, the
    axis on the in-process controller's bus (core 1, no pulse card, the bus opened).  The
    value is :func:`homing_calls.homing_status`'s, read the same way (past the axis bank's
    guard: a banked axis stays banked) without a look-up made per call: each axis's own
    per-axis states (gtecat._attrs.PerObject) are kept, and a run's state found in them.
    Its other cases (the link lost, 6041h not mapped, a run with a reason to note beside the
    0) and any other shape: the table path, with its code and reason."""
    from .._attrs import extensions
    from .args import _scalar_types
    from .table import FUNCTIONS

    ok = _scalar_types(FUNCTIONS[name].params[1])
    getattribute = object.__getattribute__  # (past the axis bank's guard, as homing_status)
    from ..controller.axis import Axis

    axis_type = Axis  # (a guarded axis, the bank's, is of another class)

    #: axis number -> [axis, its per-axis states, 6041h mapped, its run's state or None,
    #: how many states homing_calls had made when it looked]; homing_calls makes an axis's
    #: state once (its first run) and keeps it as long as the axis lives, so a state found is
    #: the axis's for good, and none found stays none until that count moves
    kept: dict[int, list[Any]] = {}
    _CACHES.append(kept)
    #: the name homing_calls keeps an axis's run state under, the values; set at the
    #: first call (homing_calls imports the GT layer, which imports this module)
    h: list[Any] = []

    def status(n: int) -> tuple[Any, Any] | None:
        """(the controller, axis ``n``'s homing status) where the fast path answers it, else
        None (the table path: no controller or axis, another session, a pulse card, the bus
        closed, the link lost, a case with a reason to note)."""
        try:
            ctl = session.controllers[1]
            ax = ctl.axes[n]
        except KeyError:  # no controller, no such axis: the table path says why
            return None
        m = ctl.master
        if not (
            session.plain  # (in this process, core 1)
            and ctl.clock._thread is None
            and ctl.card is None
            and m is not None
            and m.opened
        ):
            return None
        try:
            k = kept[n]
        except KeyError:
            k = None
        if k is None or k[0] is not ax:
            if not h:
                from . import homing_calls as hc

                h.extend((hc._STATE.name, hc.HOMING_IN_PROGRESS, hc.HOMING_FAILED, hc.MADE))
            if len(kept) > 4096:
                kept.clear()
            io = getattribute(ax, "io")
            mapped = io.get(0x6041) is not None
            k = kept[n] = [ax, extensions(ax), mapped, None, -1]
        st = k[3]
        if st is None and k[4] != h[3][0]:  # (a state made since: look again)
            k[4] = h[3][0]
            st = k[3] = k[1].get(h[0])
        lost = ax.link_lost if type(ax) is axis_type else getattribute(ax, "link_lost")
        if lost:
            return None
        if st is None:  # no run since the bus came up: not homed
            v = h[2] if k[2] else None
        elif st.active:
            v = None if st.hint is not None else h[1]
        else:
            v = st.result
        return None if v is None else (ctl, v)

    gt = status_reader(name, slow, session, advance, status, ok)
    gated = GATED

    def value(n: int) -> Any:
        """The C entry's value (asked while the GT_ gate is open: ``GATED[0]`` the
        in-process lockstep controller): ``status``'s steps past its session checks, for
        an axis seen before (else _NO: the Python function looks at it first)."""
        ctl = gated[0]
        try:
            ax = ctl.axes[n]
            k = kept[n]
        except KeyError:  # no such axis, or not seen yet
            return _NO
        m = ctl.master
        if k[0] is not ax or ctl.card is not None or m is None or not m.opened:
            return _NO
        st = k[3]
        if st is None and k[4] != h[3][0]:  # (a state made since: look again)
            k[4] = h[3][0]
            st = k[3] = k[1].get(h[0])
        if ax.link_lost if type(ax) is axis_type else getattribute(ax, "link_lost"):
            return _NO
        if st is None:  # no run since the bus came up: not homed
            if not k[2]:
                return _NO
            v = h[2]
        elif st.active:
            if st.hint is not None:
                return _NO
            v = h[1]
        else:
            v = st.result
            if v is None:
                return _NO
        session.last = None
        return v

    return _entry(  # type: ignore[no-any-return]
        gt, value, ok, centry.INT, gate=centry.GT_GATE, after=_after(advance, name, 0)
    )


def struct_packer(cls: type) -> Callable[..., None] | None:
    """``pack(s, 0, *values)``: every field of structure class ``cls`` written at once, the
    same bytes as setting the fields one by one (the same C type per field, its offset, the
    trailing padding untouched); ``struct.error`` for a value a field's type cannot hold,
    where the field's own setter would wrap it (the caller then sets the fields).  None for
    a class with other fields than plain numbers, bit fields or padding between fields."""
    codes = {1: "b", 2: "h", 4: "i", 8: "q"}
    fmt, pos = "=", 0
    try:
        for field in cls._fields_:  # type: ignore[attr-defined]
            if len(field) != 2:
                return None  # (a bit field)
            name, t = field
            code = getattr(t, "_type_", None)
            size = ctypes.sizeof(t)
            if not isinstance(code, str) or code in "?cuzZPOv":
                return None
            if getattr(cls, name).offset != pos:
                return None  # (padding between fields: struct's pad bytes would write it)
            if code in "fd":
                fmt += code
            elif size in codes:
                fmt += codes[size] if code.islower() else codes[size].upper()
            else:
                return None
            pos += size
    except (AttributeError, TypeError, ValueError):
        return None
    packer = struct.Struct(fmt)
    if packer.size != pos or pos > ctypes.sizeof(cls):
        return None
    return packer.pack_into


def trap_prm_into(res: Any, s: Any) -> None:
    """GT_GetTrapPrm's fields, from the profile's Trap parameters (its table path's too)."""
    prm = res.profile.trap_prm
    try:
        _PACK_TRAP(s, 0, prm.acc, prm.dec, prm.vel_start, prm.smooth_time)  # type: ignore[misc]
    except (struct.error, TypeError):  # (a value a field wraps: the fields' own setters)
        s.acc, s.dec, s.velStart, s.smoothTime = prm.acc, prm.dec, prm.vel_start, prm.smooth_time


def _pack_trap() -> Any:
    from .structs import TTrapPrm

    pack = struct_packer(TTrapPrm)
    if pack is None or [f[0] for f in TTrapPrm._fields_] != [
        "acc",
        "dec",
        "velStart",
        "smoothTime",
    ]:

        def pack(s: Any, _: int, *values: Any) -> None:
            raise TypeError  # (the fields' own setters)

    return pack


_PACK_TRAP = _pack_trap()


def _trap_bytes() -> tuple[Callable[[Any], bytes], int] | None:
    """GT_GetTrapPrm's structure as bytes (what :func:`trap_prm_into` packs into it) and
    how many, for its C entry; None where the structure is not packed at once."""
    packer = getattr(_PACK_TRAP, "__self__", None)
    if not isinstance(packer, struct.Struct):
        return None
    pack = packer.pack

    def to_bytes(res: Any) -> bytes:
        prm = res.profile.trap_prm
        return pack(prm.acc, prm.dec, prm.vel_start, prm.smooth_time)

    to_bytes.pack = pack  # type: ignore[attr-defined]  # (its C entry's value: inline)
    to_bytes.inline = (
        "prm = prof.trap_prm\nb = PACK(prm.acc, prm.dec, prm.vel_start, prm.smooth_time)"  # type: ignore[attr-defined]
    )
    return to_bytes, packer.size


#: a structure reader's structure as bytes: function -> (``to_bytes(resources)``, how many)
STRUCT_BYTES = {k: v for k, v in {"GT_GetTrapPrm": _trap_bytes()}.items() if v is not None}


def _struct_readers() -> dict[str, tuple[type, Any, Callable[[Any, Any], None]]]:
    from ..controller.profile import PrfMode
    from .structs import TTrapPrm

    return {"GT_GetTrapPrm": (TTrapPrm, PrfMode.TRAP, trap_prm_into)}


#: readers of one structure of one axis's profile: function -> (the structure, the profile
#: mode the function needs, ``fill(resources, structure)``: the table path's own)
STRUCT_READERS = _struct_readers()


def fast_struct_reader(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """``GT_GetTrapPrm(profile, p)`` with the fast path in front of the table: ``p``
    ``byref(s)`` (no offset) or ``s`` itself of the structure's own class, an axis of the
    in-process controller (core 1, no pulse card) in the mode the function needs; the table
    path's own ``fill`` writes the fields, a banked axis staying in the bank (what it reads
    is set by GT calls only).  Any other shape, another mode, an axis that does not exist:
    the table path, with its code and reason."""
    from .table import FUNCTIONS

    first = FUNCTIONS[name].params[0]
    if first.name not in ("axis", "profile", "encoder") or any(
        q.name == "count" for q in FUNCTIONS[name].params
    ):  # (the readers of one axis's set-up only)
        raise ValueError(f"{name}: not a function of one axis")
    cls, mode, fill = STRUCT_READERS[name]
    target = _target([cls])
    one = frozenset([cls])
    arrays: dict[type, bool] = {}

    def is_array(tp: type) -> bool:
        """An array of the structure (at least one): its first element takes it."""
        ok = arrays.get(tp)
        if ok is None:
            ok = arrays[tp] = issubclass(tp, ctypes.Array) and tp._type_ is cls and tp._length_ >= 1
        return ok

    def ready(n: int) -> Any:
        """(the controller, axis ``n``'s resources) where the fast path answers, else None
        (the table path: no controller or axis, another session, a pulse card)."""
        try:
            ctl = session.controllers[1]
            res = ctl.resources[n]
        except KeyError:  # no controller, no such axis: the table path says why
            return None
        if (
            session.plain  # (in this process, core 1)
            and ctl.card is None
            and ctl.clock._thread is None
            and ctl.axes.get(n) is res.ax
        ):
            return ctl, res
        return None

    def gt(n: Any = _NO, p: Any = _NO, /, *extra: Any, **kw: Any) -> int:
        if type(n) is int and not kw and not extra:
            tp = type(p)
            if tp is _CArg:
                s = target(p)
                if s is p:  # byref(array[, offset]): the structure there (C's &prm[k])
                    s = element_at(p, one)
            elif tp is cls:
                s = p
            else:  # an array of structures: its first (ctypes' element shares its memory)
                s = p[0] if is_array(tp) else None
            got = None if s is None else ready(n)
            if got is not None:
                ctl, res = got
                # (no release from the axis bank, unlike the table path: the profile's mode
                # and its Trap parameters are set by GT calls only, which give the axis back
                # first, so a banked axis's are its own)
                if res.profile.mode is mode:
                    try:
                        fill(res, s)
                    except Exception:  # (the table path raises it again: its code)
                        return slow(n, p)
                    session.last = None
                    clock = ctl.clock
                    if clock.mode is _LOCKSTEP:
                        return 0
                    return advance(ctl, name, 0)
        return slow(*(a for a in (n, p) if a is not _NO), *extra, **kw)

    gt.slow = slow  # type: ignore[attr-defined]
    packed = STRUCT_BYTES.get(name)
    if packed is None:
        return gt
    to_bytes, size = packed

    env = {"_NO": _NO, "MODE": mode, "TO_BYTES": to_bytes, "session": session}
    env["PACK"] = getattr(to_bytes, "pack", None)
    inline = getattr(to_bytes, "inline", "b = TO_BYTES(res)")  # (to_bytes' steps inline)
    code = _STRUCT_VALUE.replace("{bytes}", "\n".join("        " + x for x in inline.split("\n")))
    exec(_compiled_code(code, f"<gt struct value {name}>"), _gated(env))
    value = env["value"]

    def first(n: Any, count: Any, tp: type, clock: Any) -> Any:
        """The C entry's bytes for an array of the structure (or byref of one, with an
        offset too: its entry checks the room): the first element's, as ``gt`` writes it."""
        if count != 1 or clock is not None or not is_array(tp):
            return _NO
        return value(n)

    return _entry(  # type: ignore[no-any-return]
        gt, value, [cls], centry.BYTES, size, centry.GT_GATE, _after(advance, name, 0),
        array=first,
    )  # fmt: skip


#: a structure reader's value for its C entry (asked while the GT_ gate is open: CTL the
#: in-process lockstep controller): the structure's bytes (``{bytes}``: to_bytes' steps),
#: else _NO
_STRUCT_VALUE = """
def value(n):
    ctl = CTL
    try:
        res = ctl.resources[n]
    except KeyError:  # no such axis: the table path says why
        return _NO
    ax = res.ax
    if ctl.card is not None or ctl.axes.get(n) is not ax:
        return _NO
    prof = res.profile  # (a banked axis's own: the fast function's note)
    if prof.mode is not MODE:
        return _NO
    try:
{bytes}
    except Exception:  # (a value a field wraps: the Python path's field setters)
        return _NO
    session.last = None
    return b
"""


#: the smart homing's status reader on the fast path (a homing loop polls it)
HOME_STATUS = "GT_GetHomeStatus"
#: THomeStatus's fields in order (run, stage, error, pad1, capturePos, targetPos), natively
_HOME_STATUS = struct.Struct("@hhhhii")


def smart_home_lookup() -> tuple[Callable[[Any, int], Any], dict[int, tuple[Any, Any]]]:
    """``home_of(ctl, n)``: axis ``n``'s smart homing on ``ctl`` where a fast path reads it,
    else None (no such axis, a pulse card, a homing the table path has not made yet); and
    what it keeps: axis number -> (its resources, their smart homing) (smart_home makes a
    homing once per resources and keeps it while they live, so one found is theirs for good).
    The smart homing status's fast path and the older cards' homing status share it."""
    from ..controller import smart_home as sh

    homes, running = sh._HOMES, sh._RUNNING
    kept: dict[int, tuple[Any, Any]] = {}
    _CACHES.append(kept)

    def home_of(ctl: Any, n: int) -> Any:
        try:
            res = ctl.resources[n]
        except KeyError:  # no such axis: the table path says why
            return None
        if ctl.axes.get(n) is not res.ax or ctl.card is not None:
            return None
        k = kept.get(n)
        if k is not None and k[0] is res:
            return k[1]
        home = homes.get(res)
        if home is None or ctl not in running:  # (the table path makes it, registered)
            return None
        if len(kept) > 4096:
            kept.clear()
        kept[n] = (res, home)
        return home

    return home_of, kept


def fast_home_status(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """``GT_GetHomeStatus(axis, p)`` with the fast path in front of the table: ``p``
    ``byref(s)`` (no offset) or ``s`` itself of THomeStatus, an axis of the in-process
    controller (no pulse card) whose smart homing the table path has made before (its
    first call, or GT_GoHome's); the fields as the table path sets them.  Any other shape,
    a value a field would wrap, a homing not made yet: the table path (GTN_GetHomeStatus
    with core 1 takes this path through the GT layer's twin)."""
    from .home_structs import THomeStatus

    fields = [(f[0], f[1]) for f in THomeStatus._fields_]
    i16, i32 = ctypes.c_int16, ctypes.c_int32
    want = [("run", i16), ("stage", i16), ("error", i16), ("pad1", i16)]
    want += [("capturePos", i32), ("targetPos", i32)]
    if fields != want or ctypes.sizeof(THomeStatus) != _HOME_STATUS.size:
        # (another layout: the table path alone)
        return slow
    pack, pack_into = _HOME_STATUS.pack, _HOME_STATUS.pack_into
    target = _target([THomeStatus])
    home_of, kept = smart_home_lookup()

    def gt(n: Any = _NO, p: Any = _NO, /, *extra: Any, **kw: Any) -> int:
        if type(n) is int and not kw and not extra:
            tp = type(p)
            if tp is _CArg:
                s = target(p)
                if s is p:
                    s = None
            else:
                s = p if tp is THomeStatus else None
            ctl = None if s is None else session.controllers.get(1)
            if ctl is not None and session.plain and ctl.clock._thread is None:
                home = home_of(ctl, n)
                if home is not None:
                    st = home.status
                    try:
                        pack_into(
                            s, 0, int(st.run), int(st.stage), int(st.error), 0,
                            int(st.capturePos), int(st.targetPos),
                        )  # fmt: skip
                    except Exception:  # (a value a field wraps, or no number: the table)
                        return slow(n, p)
                    session.last = None
                    if ctl.clock.mode is _LOCKSTEP:
                        return 0
                    return advance(ctl, name, 0)
        return slow(*(a for a in (n, p) if a is not _NO), *extra, **kw)

    gt.slow = slow  # type: ignore[attr-defined]
    gated = GATED

    def value(n: int) -> Any:
        """The C entry's value (asked while the GT_ gate is open): the structure's bytes
        (home_of's steps inline for an axis seen before)."""
        ctl = gated[0]
        try:
            res = ctl.resources[n]
            k = kept[n]
        except KeyError:  # no such axis, or not seen: home_of looks
            home = home_of(ctl, n)
            if home is None:
                return _NO
        else:
            if ctl.axes.get(n) is not res.ax or ctl.card is not None:
                return _NO
            home = k[1] if k[0] is res else home_of(ctl, n)
            if home is None:
                return _NO
        st = home.status
        try:  # (ints and IntEnums as they are: pack takes their value, as int() gives it)
            b = pack(st.run, st.stage, st.error, 0, st.capturePos, st.targetPos)
        except Exception:  # (a float, say: int() first, as the table path)
            try:
                b = pack(
                    int(st.run), int(st.stage), int(st.error), 0,
                    int(st.capturePos), int(st.targetPos),
                )  # fmt: skip
            except Exception:  # (a value a field wraps, or no number: the table path)
                return _NO
        session.last = None
        return b

    return _entry(  # type: ignore[no-any-return]
        gt,
        value,
        [THomeStatus],
        centry.BYTES,
        _HOME_STATUS.size,
        centry.GT_GATE,
        _after(advance, name, 0),
    )


#: the session's core reader on the fast path (it reads no controller)
CORE = "GT_GetCore"


def fast_core(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """``GT_GetCore(p)`` with the fast path in front of the table: ``p`` ``byref(x)`` (no
    offset) or ``x`` of an integer type the pointer takes, in this process (attached: the
    controller process answers, the table path); then the call's host latency as the table
    path runs it (on the selected core's controller, none in lockstep)."""
    from .args import _scalar_types
    from .table import FUNCTIONS

    ok = _scalar_types(FUNCTIONS[name].params[0])
    target = _target(ok)
    first = _array_first(ok)

    def gt(p: Any = _NO, /, *extra: Any, **kw: Any) -> int:
        if not kw and not extra and session.local:
            # (an array: its first element, of a type that holds 1..4)
            obj, arr = _value_target(p, target, ok, first)
            if obj is not None and session.note is None:
                core = session._core  # (1..4: every integer type the pointer takes holds it)
                if arr is None:
                    obj.value = core
                else:
                    obj[0] = core
                session.last = None
                ctl = session.controllers.get(core)
                if ctl is None or ctl.clock.mode is _LOCKSTEP:
                    return 0
                return advance(ctl, name, 0)
        return slow(*(a for a in (p,) if a is not _NO), *extra, **kw)

    gt.slow = slow  # type: ignore[attr-defined]

    def value() -> Any:  # (asked while the GT_ gate is open: this process, core 1)
        if session.note is not None:
            return _NO
        session.last = None
        return session._core

    return _noaxis_entry(gt, value, ok, name, advance)


def _noaxis_entry(
    gt: Any, value: Callable[[], Any], ok: Any, name: str, advance: Callable[..., int]
) -> Any:
    """A one-pointer reader's public function ``f(p)``: its C entry (gated by the GT_ gate,
    ``value()`` the value; ``p`` ``byref(x)`` or ``x`` of an integer type of ``ok``, or a
    one-dimensional numpy array of one: its first element) in front of its Python fast
    function ``gt``, where :data:`CENTRY` is on and the entry is available; else ``gt``."""
    if not CENTRY:
        return gt
    types = sorted((t for t in ok if getattr(t, "_type_", "") in _INT_CODES), key=str)
    entry = centry.reader(
        gt, value, _NO, types, centry.INT, most=1, noaxis=True, gate=centry.GT_GATE,
        after=_after(advance, name, 0), numpy=_int_dtypes(types),
        array=_first_element(lambda _: value(), types),  # (a ctypes array: its first element)
    )  # fmt: skip
    if entry is None:
        return gt
    entry.slow, entry.python = getattr(gt, "slow", gt), gt
    return entry


def _int_dtypes(types: Any) -> list[Any]:
    """The numpy dtypes of the integer ctypes ``types`` (the same size and sign: the Python
    fast paths' first element of a numpy array, :func:`_array_first`)."""
    out = {
        np.dtype(f"{'i' if t._type_.islower() else 'u'}{ctypes.sizeof(t)}")
        for t in types
        if getattr(t, "_type_", "") in _INT_CODES
    }
    return sorted(out, key=str)


#: the card's IO readers on the fast path: function -> (the types it reads, first and last,
#: and where its readers are kept among a controller's ``input_plans``: type + this)
IO_READERS = {"GT_GetDi": (0, 6, 0), "GT_GetDiRaw": (0, 6, 16), "GT_GetDo": (10, 12, 32)}


def _value_target(
    p: Any, target: Callable[[Any], Any], ok: Any, first: Callable[[Any, type], Any]
) -> tuple[Any, Any]:
    """Where a one-value reader's Python path writes: ``(x, None)`` for ``byref(x)`` with no
    offset (``target``) or ``x`` itself of one of ``ok``, ``(array, bounds)`` for an array
    whose first element takes the value (``first``: the range that element holds; ``p``, or
    the elements ``byref(array[, offset])`` points at), else ``(None, None)`` (the table path
    answers)."""
    tp = type(p)
    if tp is _CArg:
        obj = target(p)
        if obj is not p:
            return obj, None
        p = array_at(p)  # byref(array[, offset]): its elements from there
        if p is None:
            return None, None
        tp = type(p)
    if tp in ok:
        return p, None
    arr = first(p, tp)
    return (None, None) if arr is None else (p, arr)


def _int_bounds(types: Any) -> dict[type, tuple[int, int]]:
    """The range of values each ctypes integer type of ``types`` holds."""
    out = {}
    for t in types:
        bits = 8 * ctypes.sizeof(t)
        out[t] = (
            (0, (1 << bits) - 1)
            if t._type_.isupper()
            else (-(1 << (bits - 1)), (1 << (bits - 1)) - 1)
        )
    return out


def _array_first(ok: Any) -> Callable[[Any, type], tuple[int, int] | None]:
    """``first(p, type(p))`` for a fast reader of one integer into a pointer the table path
    takes as the ctypes types ``ok``: the range of values the first element of ``p`` holds
    when ``p`` is a ctypes array of one of ``ok`` (at least one element) or a writable
    one-dimensional numpy array of an integer dtype of the size and sign of one of ``ok``
    (the table path's ``flat[:1] = [value]``), else None (the table path decides)."""
    bounds = _int_bounds(t for t in ok if t._type_ in "bBhHiIlLqQ")
    dtypes = {
        np.dtype(f"{'i' if t._type_.islower() else 'u'}{ctypes.sizeof(t)}"): b
        for t, b in bounds.items()
    }
    arrays: dict[type, tuple[int, int] | None] = {}

    def first(p: Any, tp: type) -> tuple[int, int] | None:
        if tp is _NDARRAY:
            b = dtypes.get(p.dtype)
            if (
                b is not None
                and p.ndim == 1
                and p.size
                and p.flags.writeable
                and p.flags.c_contiguous  # (a strided view: the table path's 7)
            ):
                return b
            return None
        try:
            return arrays[tp]
        except KeyError:
            b = arrays[tp] = (
                bounds.get(tp._type_) if issubclass(tp, ctypes.Array) and tp._length_ >= 1 else None
            )
            return b

    return first


def fast_io_reader(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """``GT_GetDi(diType, p)``, ``GT_GetDiRaw`` and ``GT_GetDo(doType, p)`` with the fast
    path in front of the table: the type one of those the function reads, ``p`` a ``byref``
    (no offset) or the object itself of an integer type the pointer takes, or a ctypes or
    numpy array of one (its first element), on the in-process controller (core 1).  The
    value is the table path's (:func:`io_calls.read_di`, :func:`io_calls.read_do`) through a
    reader of :func:`io_calls.io_reader` (for the inputs: each axis's bit read live from the
    process image, its sense folded in), kept per controller and type until the next
    :func:`gtecat.controller.input_sense.changed` (every change of a configuration's
    ``reverse``, a bus brought up with other axes).  The axis bank gives its axes back
    first, as it does before the table path.  Any other shape, a value the type cannot
    hold, another type: the table path, with its code and reason."""
    from ..controller.input_sense import keep
    from .args import _scalar_types
    from .table import FUNCTIONS

    proto = FUNCTIONS[name]
    ok = _scalar_types(proto.params[1])
    bounds = _int_bounds(ok)
    #: the types that hold every value (a signed 32-bit word): no range check
    T0 = ctypes.c_long  # (the usual one)
    wide = frozenset(
        t for t, (lo, hi) in bounds.items() if lo <= -(1 << 31) and (1 << 31) <= hi + 1
    )
    target = _target(ok)
    lo_t, hi_t, kind = IO_READERS[name]
    made: list[Any] = []  # io_calls.io_reader (io_calls imports the GT layer: at first use)
    first = _array_first(ok)

    def plan(ctl: Any, t: int) -> Any:
        """The reader of type ``t`` on ``ctl``, made and kept (until the next change)."""
        if not made:
            from .io_calls import io_reader

            made.append(io_reader)
        return keep(ctl, t + kind, made[0](ctl, name, t))

    env = {
        "_NO": _NO,
        "_CArg": _CArg,
        "_LOCKSTEP": _LOCKSTEP,
        "session": session,
        "slow": slow,
        "advance": advance,
        "name": name,
        "proto": proto,
        "target": target,
        "ok": ok,
        "T0": T0,
        "wide": wide,
        "bounds": bounds,
        "first": first,
        "array_at": array_at,
        "plan": plan,
        # the inputs' readers keep the bank's axes (bank.BANK_READS: they read the image),
        # and so does GT_GetDo (its outputs are the controller's; the enabled axes' bits
        # of the bank's rows from the rows: io_calls.do_reader)
        "RELEASES": name not in BANK_READS and name != "GT_GetDo",
    }
    # (compiled with the function's type range and key offset as constants, its names as
    # globals: the fewest steps per call)
    code = _IO_READER.format(lo=lo_t, hi=hi_t, kind=kind)
    exec(_compiled_code(code, f"<gt fast io {name}>"), env)
    gt = env["gt"]
    gt.slow = slow  # type: ignore[attr-defined]
    _gated(env)
    exec(_compiled_code(_IO_VALUE.format(lo=lo_t, hi=hi_t, kind=kind), f"<gt io {name}>"), env)
    return _entry(  # type: ignore[no-any-return]
        gt, env["value"], ok, centry.INT, gate=centry.GT_GATE, after=_after(advance, name, 0)
    )


#: fast_io_reader's function (``{lo}``..``{hi}``: the types it reads; ``{kind}``: its readers'
#: offset among a controller's ``input_plans``)
_IO_READER = """
def gt(t=_NO, p=_NO, /, *extra, **kw):
    if type(t) is int and {lo} <= t <= {hi} and session.plain and not extra and not kw:
        try:
            ctl = session.controllers[1]
            read = ctl.input_plans[t + {kind}]
        except KeyError:  # none kept (yet, or since a change), no controller
            ctl = session.controllers.get(1)
            read = None
        if ctl is not None:
            clock = ctl.clock
            if clock._thread is None and session.note is None:
                tp = type(p)
                q = p
                if tp is _CArg:
                    obj = target(p)
                    if obj is p:  # byref(array[, offset]): its elements from there
                        q = array_at(p)
                        b = None if q is None else first(q, type(q))
                        obj = _NO if b is None else None
                elif tp is T0 or tp in ok:
                    obj = p
                else:
                    b = first(p, tp)  # (an array: its first element)
                    obj = _NO if b is None else None
                if obj is not _NO:
                    bank = ctl.bank
                    if RELEASES and bank is not None and bank.n_alive:  # (GT_GetDo: what
                        bank.before_call(ctl, proto, (t, p))  # the table path does first)
                    if read is None:
                        read = plan(ctl, t)
                    v = read()
                    if obj is not None:
                        k = type(obj)
                        done = k is T0 or k in wide or bounds[k][0] <= v <= bounds[k][1]
                        if done:
                            obj.value = v
                    else:  # an array's first element
                        done = b[0] <= v <= b[1]
                        if done:
                            q[0] = v
                    if done:  # (else a value the type cannot hold: the table's code)
                        session.last = None
                        if clock.mode is _LOCKSTEP:
                            return 0
                        return advance(ctl, name, 0)
    return slow(*(a for a in (t, p) if a is not _NO), *extra, **kw)
"""


#: an IO reader's value for its C entry (the common case of ``_IO_READER``: a reader kept,
#: the lockstep clock, no axis of the bank to give back first); else _NO
#: (asked while the GT_ gate is open: CTL the in-process lockstep controller)
_IO_VALUE = """
def value(t):
    if {lo} <= t <= {hi} and session.note is None:
        try:
            read = CTL.input_plans[t + {kind}]
        except KeyError:  # none kept (yet, or since a change)
            return _NO
        if RELEASES:
            bank = CTL.bank
            if bank is not None and bank.n_alive:
                return _NO
        v = read()
        session.last = None
        return v
    return _NO
"""


#: readers of several values polled in loops (a capture's status and value, a coordinate
#: system's run flag and segments): function -> what each argument after the outputs must be
#: for the C entry (centry.multi: GT_GetCaptureStatus' count 1 and pClock NULL, GT_CrdStatus'
#: FIFO 0)
MULTI_READERS: dict[str, tuple[int, ...]] = {
    "GT_GetCaptureStatus": (centry.ONE, centry.NULL),
    "GT_CrdStatus": (centry.ZERO,),
}


def fast_multi(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """A reader of several values with its C entry in front of the table path
    (:func:`centry.multi`): the common shape - the number, ``byref(x)`` or ``x`` of an
    integer type each output takes, the arguments after them as :data:`MULTI_READERS` says
    - on the in-process controller (the GT_ gate), an axis or system that exists and is
    set up (a capture made by GT_SetCaptureMode or an earlier read, a system with its
    parameters); its values as the table path stores them, a banked axis left in the bank
    (what it reads is the capture unit's and the system's own, kept current by the bank's
    cycles).  Every other call: the table path, with its code and reason."""
    from .args import _scalar_types
    from .table import FUNCTIONS

    if not CENTRY:
        return slow
    params = FUNCTIONS[name].params
    outs = []
    for q in params[1:3]:
        ts = [t for t in _scalar_types(q) if getattr(t, "_type_", "") in _INT_CODES]
        outs.append((sorted(ts, key=str), centry.INT))
    value = _MULTI_VALUES[name](session)
    entry = centry.multi(
        slow, value, _NO, outs, MULTI_READERS[name], centry.GT_GATE, _after(advance, name, 0)
    )
    if entry is None:
        return slow
    entry.python = slow  # type: ignore[attr-defined]  # (no Python fast function: the table)
    return entry  # type: ignore[no-any-return]


def _capture_value(session: Any) -> Callable[[Any], Any]:
    """GT_GetCaptureStatus' (status, value) of a capture made already, else _NO."""
    from ..controller.capture import _UNITS

    def value(n: Any) -> Any:
        ctl = GATED[0]
        try:
            res = ctl.resources[n]
        except KeyError:  # no such axis: the table path says why
            return _NO
        if ctl.card is not None or ctl.axes.get(n) is not res.ax:
            return _NO
        unit = _UNITS.get(res)
        if unit is None:  # (not made yet: the table path makes it)
            return _NO
        session.last = None
        return (unit.status, unit.value)

    return value


def _crd_value(session: Any) -> Callable[[Any], Any]:
    """GT_CrdStatus' (run, segments done) of FIFO 0 of a system with its parameters."""

    def value(n: Any) -> Any:
        ctl = GATED[0]
        if ctl.card is not None:
            return _NO
        systems = vars(ctl).get("crd_bank")  # (made by the table path's first call)
        c = None if systems is None else systems.systems.get(n)
        if c is None or c.prm is None:  # (the table path says why)
            return _NO
        now = c.now()
        session.last = None
        return (1 if now.running and now.fifo == 0 else 0, now.segments_done[0])

    return value


_MULTI_VALUES: dict[str, Callable[[Any], Callable[[Any], Any]]] = {
    "GT_GetCaptureStatus": _capture_value,
    "GT_CrdStatus": _crd_value,
}


WAIT = "GTE_Wait"
_REALTIME = ClockMode.REALTIME


def wait_yield(ctl: Any) -> None:
    """The end of a GTE_Wait (its docstring): a yield in virtual time while a panel or
    verb is attached to the inspection endpoint.  (The endpoint module is there once
    something published an endpoint: GT_Open, a controller process; a process that never
    did has nobody attached.)"""
    endpoints = sys.modules.get("gtecat.inspect.endpoint")
    if (
        endpoints is not None
        and endpoints._PUBLISHED
        and ctl.clock.mode is not _REALTIME
        and endpoints.attached()
    ):
        time.sleep(0)


def fast_wait(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """``GTE_Wait(ms)`` with the fast path in front of the table: ``ms`` a plain int or float
    from 0 to one slice of a long wait (Controller.WAIT_SLICE_NS), on the in-process
    controller of core 1 on the lockstep or the auto clock - the table path's call without
    its binder and layers, the wait's common case in one call (Controller.wait_quick, else
    Controller.wait_ms); anything else (a negative, NaN or huge value, None, a keyword)
    takes the table path, its code and reason."""
    from ..controller.core import Controller
    from ._core import call_done, call_failed

    most = Controller.WAIT_SLICE_NS // 1_000_000

    def gt(ms: Any = _NO, /, *extra: Any, **kw: Any) -> int:
        tp = type(ms)
        if (
            (tp is int or tp is float)
            and 0 <= ms <= most  # (a float's NaN: never)
            and not extra
            and not kw
            and session.plain
        ):
            ctl = session.controllers.get(1)
            if ctl is not None and ctl.card is None:
                clock = ctl.clock
                if clock.mode is not _REALTIME:
                    try:
                        with clock.lock:  # (the table path's: a call's cycles, one thread's)
                            # (a float's ns as wait_ms rounds them: GTE_Wait(1.0), as a
                            # program that computes its wait passes it)
                            total = ms * 1_000_000 if tp is int else round(ms * 1_000_000)
                            if not ctl.wait_quick(total):
                                ctl.wait_ms(float(ms))
                            wait_yield(ctl)
                    except Exception as e:
                        return call_failed(name, e, ctl, 1)
                    if session.note is None:
                        session.last = None
                    else:
                        call_done(name)
                    if clock.mode is _LOCKSTEP:
                        return 0
                    return advance(ctl, name, 0)
        return slow(*(a for a in (ms,) if a is not _NO), *extra, **kw)

    gt.slow = slow  # type: ignore[attr-defined]  # the table path (tests compare both)
    return _wait_entry(gt, name, session, advance)


def call_ended(session: Any, ctl: Any, name: str, advance: Callable[[Any, str, int], int]) -> int:
    """What the GT layer does after a call that returned 0 (``_core.gt_function``'s run):
    the session's last failure cleared, or the call's note kept; the call's host latency on
    the auto clock."""
    if session.note is None:
        session.last = None
    else:
        from ._core import call_done

        call_done(name)
    if ctl.clock.mode is _LOCKSTEP:
        return 0
    return advance(ctl, name, 0)


def _wait_entry(
    gt: Callable[..., int], name: str, session: Any, advance: Callable[[Any, str, int], int]
) -> Callable[..., int]:
    """GTE_Wait's public function: its C entry (:func:`centry.wait`: the wait run on the
    quick cycle armed for the readers' entries, on the lockstep and the auto clock) in
    front of the fast function ``gt``, where :data:`CENTRY` is on and the entry is
    available; else ``gt``."""
    if not CENTRY:
        return gt
    from ..controller.bank_kernel import IN_MAXC
    from ..controller.core import Controller
    from ._core import call_failed

    def rest(rc: int, pending: int) -> int:
        # (the entry ran the wait's cycles on the armed call, its book in C declined them:
        # the controller's book and the rest of the wait, then the fast function's end)
        ctl = GATED[0]
        try:
            ctl.waited(rc, pending)
            wait_yield(ctl)
        except Exception as e:
            return call_failed(name, e, ctl, 1)
        return call_ended(session, ctl, name, advance)

    entry = centry.wait(
        gt, _after(advance, name, 0), rest, vars(session),
        Controller.WAIT_SLICE_NS // 1_000_000, Controller.BATCH_CYCLES, IN_MAXC,
    )  # fmt: skip
    if entry is None:
        return gt
    Controller.C_WAITS = True  # (a wait arms the next cycle for it, lockstep too)
    entry.slow, entry.python = gt.slow, gt  # type: ignore[attr-defined]
    return entry  # type: ignore[no-any-return]


def _makers() -> dict[str, Callable[..., Callable[..., int]]]:
    out: dict[str, Callable[..., Callable[..., int]]] = {
        WAIT: fast_wait,
        CLOCK: fast_clock,
        READY: fast_ready,
        **dict.fromkeys(IO_READERS, fast_io_reader),
        CORE: fast_core,
        HOMING: fast_homing_status,
        HOME_STATUS: fast_home_status,
        HOME_STS: fast_home_sts,  # (the older cards' homing status: its own module)
        BIT_WRITE: fast_bit_write,
    }
    for names, make in (
        (MULTI_READERS, fast_multi),
        (READERS, fast_reader),
        (RAW, fast_raw),
        (ECAT_READERS, fast_ecat_reader),
        (STRUCT_READERS, fast_struct_reader),
    ):
        out.update(dict.fromkeys(names, make))
    return out


#: function -> the maker of its fast path, ``make(name, slow, session, advance)`` (the GT
#: layer puts it in front of the table-checked function)
FAST_MAKERS = _makers()
for _name in fast_functions() - frozenset(READERS) - RAW:
    SLOW_SHAPES.setdefault(_name, {})["memoryview"] = _VIEW_REASON
