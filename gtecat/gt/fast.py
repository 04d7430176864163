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
import struct
from collections.abc import Callable
from typing import Any

from ..controller.resources import AxisResources
from ..master.clock import ClockMode

_CArg = type(ctypes.byref(ctypes.c_int()))
_seen: dict[int, tuple[Any, str]] = {}  # id -> (object, repr of byref(object)), recent ones
_NO: Any = object()  # an argument the caller did not pass
_addressof = ctypes.addressof


_status = AxisResources.status
_LOCKSTEP = ClockMode.LOCKSTEP


def attr_getter(name: str) -> Callable[[Any], float]:
    """One axis's reading ``name`` as a double (the table readers of motion_calls use it too)."""

    def get(r: Any) -> float:
        return float(getattr(r, name))

    return get


_INTS = frozenset({ctypes.c_int32, ctypes.c_long, ctypes.c_int64, ctypes.c_longlong})
_DOUBLE = frozenset({ctypes.c_double})

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
}


def fast_reader(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """``slow`` (the table-checked GT function) with the fast path in front of it;
    ``advance(ctl, name, rc)`` runs the call's host latency, catching what the cycle raises."""
    get, ctypes_ok = READERS[name]
    last: list[Any] = [None]  # the last byref object checked (kept alive, so never reused)
    array_types: dict[type, bool] = {}

    def is_array(tp: type) -> bool:
        ok = array_types.get(tp)
        if ok is None:
            ok = array_types[tp] = (
                issubclass(tp, ctypes.Array) and tp._type_ in ctypes_ok and tp._length_ >= 1
            )
        return ok

    def gt(
        n: Any = _NO, p: Any = _NO, count: Any = _NO, pClock: Any = _NO, *extra: Any, **kw: Any
    ) -> int:
        ctl = session.controllers.get(1)
        if (
            type(n) is not int
            or extra
            or kw
            or ctl is None
            or (count is not _NO and (type(count) is not int or count != 1))
            or (pClock is not _NO and pClock is not None)
            or session.remote is not None
        ):
            return slow(*(a for a in (n, p, count, pClock) if a is not _NO), *extra, **kw)
        res = ctl.resources.get(n)
        clock = ctl.clock
        if res is None or clock._thread is not None:
            return slow(*(a for a in (n, p, count, pClock) if a is not _NO))
        tp = type(p)
        if tp is _CArg:
            obj = p._obj
            if p is not last[0]:
                # byref(obj), not byref(obj, offset): its repr names the address it holds
                # (cheaper than asking ctypes); any doubt takes the table path
                seen = _seen.get(id(obj))
                if seen is None or seen[0] is not obj:
                    if len(_seen) > 512:
                        _seen.clear()
                    seen = _seen[id(obj)] = (obj, f"<cparam 'P' ({_addressof(obj):#x})>")
                if type(obj) not in ctypes_ok or repr(p) != seen[1]:
                    return slow(*(a for a in (n, p, count, pClock) if a is not _NO))
                last[0] = p  # checked: the same pointer object next time needs no check
            obj.value = get(res)
        elif is_array(tp):
            p[0] = get(res)
        else:
            return slow(*(a for a in (n, p, count, pClock) if a is not _NO))
        session.last = None
        if clock.mode is not _LOCKSTEP:
            return advance(ctl, name, 0)
        return 0

    gt.slow = slow  # type: ignore[attr-defined]  # the table path (tests compare both)
    return gt


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
    controllers = session.controllers

    def answer(body: Any) -> bytes | None:
        if len(body) != size:
            return None
        axis, psize, _, count, pclock = unpack(body)[4:]
        ctl = controllers.get(1)
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
