"""The fast path of the calls an application streams: ``GT_PtData``, ``GT_PtSpace`` and
``GT_MoveAbsolute``.

A program refilling dynamic PT FIFOs calls them thousands of times a second (64 axes of
10 ms segments: about 6,400 points and 3,200 space reads).  The table path checks and
converts every argument generically (:mod:`gtecat.gt.args`) and costs several times the
planner's own work; here the one shape such a loop passes - plain ``int`` / ``float``
arguments, the space into ``byref`` of an integer (or the object itself) - goes to the
planner directly, on an axis the bank does not run or on a row it may keep
(:func:`gtecat.controller.bank_stream.stream_row`).  Anything else, and any call the planner
refuses, takes the table path, which answers with its own code and reason (a refused call
changes nothing, so running it again there is the same call).
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from typing import Any

from ..controller.bank import _GUARD_SET
from ..controller.bank_stream import on_row, stream_row
from ..controller.epoch import EPOCH
from ..controller.motion.pt import PtPlanner
from ..controller.profile import PrfMode
from .fast import call_ended

_NO: Any = object()
_set = object.__setattr__
_PT = PrfMode.PT
_LONG = (-(1 << 31), (1 << 31) - 1)
_SHORT = (-(1 << 15), (1 << 15) - 1)


def _planner(session: Any, n: int) -> tuple[Any, Any] | None:
    """(the in-process controller, axis ``n``'s PT planner) where the fast path may call it,
    else None: core 1 in this process, no cycle thread, no pulse card, the axis in PT mode."""
    if not session.plain:
        return None
    ctl = session.controllers.get(1)
    if ctl is None or ctl.clock._thread is not None or ctl.card is not None:
        return None
    res = getattr(ctl, "resources", {}).get(n)
    if res is None or ctl.axes.get(n) is not res.ax:
        return None
    prof = res.profile
    if prof.mode is not _PT:
        return None
    pl = prof.planner
    if PtPlanner not in type(pl).__mro__:
        return None
    return ctl, pl


#: profile -> (a weak reference to the controller, its bank's releases and layout counts
#: then, the row, whether it is a dynamic stream's, a weak reference to the bank): a PT axis
#: the bank keeps, found by the full look (:func:`_planner`, ``stream_row``) and taken again
#: without it while the bank has neither claimed nor given back a row since (a mode change,
#: a start, a stop give their axis back first); what may change from cycle to cycle is
#: looked at on every call.  Nothing of a controller is held here: a closed one goes as it
#: always did.
_ROWS: dict[int, tuple] = {}


def _pt_target(session: Any, n: int, name: str, values: tuple) -> tuple[Any, Any, Any] | None:
    """(controller, bank or None, planner) of PT axis ``n`` where ``name`` may run on it
    (:func:`_planner`; a claimed row: ``stream_row``), else None."""
    if not session.plain:
        return None
    ctl = session.controllers.get(1)
    k = _ROWS.get(n)
    if k is not None and k[0]() is ctl:
        bank = ctl.bank
        r = k[3]
        res = ctl.resources.get(n)
        if (
            res is not None
            and bank is not None
            and k[5]() is bank
            and bank.releases == k[1]
            and bank.layout == k[2]
            and bank._stepping < 0
            and not bank._opened
            and bank._frozen_call < 0
            and r not in bank._open
            and r not in bank._tp_apply
            and r not in bank._post_next
            and bank.alive[r]
            and (not k[4] or bank.pt_stream.current(r))
        ):
            return ctl, bank, res.profile.planner
    got = _planner(session, n)
    if got is None:
        return None
    ctl, pl = got
    bank = ctl.bank
    if bank is None:
        return ctl, None, pl
    r = stream_row(bank, ctl, name, values)
    if r < 0:
        return None
    stream = False
    if bank.sampled[r]:
        cl = bank._cluster_of.get(bank.group_of[r])
        stream = bool(getattr(cl, "pt_stream", False)) and "pt_stream" in bank.__dict__
        if not stream:  # (a static FIFO: the answer depends on the FIFO named)
            return ctl, bank, pl
    if len(_ROWS) > 4096:
        _ROWS.clear()
    _ROWS[n] = (weakref.ref(ctl), bank.releases, bank.layout, r, stream, weakref.ref(bank))
    return ctl, bank, pl


def _done(session: Any, ctl: Any, name: str, advance: Callable[[Any, str, int], int]) -> int:
    """What the GT layer does after a call that changed something and returned 0: the
    readers' epoch grows, then :func:`fast.call_ended`."""
    EPOCH.n += 1
    return call_ended(session, ctl, name, advance)


def fast_pt_data(
    name: str, slow: Callable[..., int], session: Any, advance: Callable[[Any, str, int], int]
) -> Callable[..., int]:
    """``GT_PtData(profile, pos, time[, type[, fifo]])`` with plain numbers."""

    def gt(
        profile: Any = _NO, pos: Any = _NO, time: Any = _NO, kind: Any = _NO, fifo: Any = _NO,
        /, *extra: Any, **kw: Any,
    ) -> int:  # fmt: skip
        args = (profile, pos, time, kind, fifo)  # (what the caller passed: the table path's)
        if kind is _NO:
            kind = 0
        if fifo is _NO:
            fifo = 0
        if (
            not extra
            and not kw
            and type(profile) is int
            and type(time) is int
            and type(kind) is int
            and type(fifo) is int
            and (type(pos) is float or type(pos) is int)
            and _LONG[0] <= time <= _LONG[1]
            and _SHORT[0] <= kind <= _SHORT[1]
            and _SHORT[0] <= fifo <= _SHORT[1]
        ):
            got = _pt_target(session, profile, name, (profile, pos, time, kind, fifo))
            if got is not None:
                ctl, bank, pl = got
                cls = type(pl)
                if cls in _GUARD_SET:  # (on_row, inline: a claimed row's planner as it is)
                    _set(pl, "__class__", cls.__base__)
                try:  # (time as checks.real takes an int: float(time))
                    PtPlanner.data(pl, float(pos), float(time), kind, fifo)
                except Exception:
                    ok = False  # (refused: the table path says why, with its code)
                else:
                    ok = True
                finally:
                    if cls is not type(pl):
                        _set(pl, "__class__", cls)
                if ok:
                    if bank is not None:
                        bank.streamed_calls += 1
                    return _done(session, ctl, name, advance)
        return slow(*(a for a in args if a is not _NO), *extra, **kw)

    return gt


def fast_pt_space(
    name: str, slow: Callable[..., int], session: Any, advance: Callable[[Any, str, int], int]
) -> Callable[..., int]:
    """``GT_PtSpace(profile, &space[, fifo])``, the space into ``byref`` of an integer or the
    object itself."""
    from .args import _scalar_types
    from .fast import _int_bounds, _target
    from .table import FUNCTIONS

    ok = _scalar_types(FUNCTIONS[name].params[1])
    bounds = _int_bounds(ok)
    target = _target(ok)

    def gt(profile: Any = _NO, p: Any = _NO, fifo: Any = _NO, /, *extra: Any, **kw: Any) -> int:
        args = (profile, p, fifo)  # (what the caller passed: the table path's)
        if fifo is _NO:
            fifo = 0
        if not extra and not kw and type(profile) is int and type(fifo) is int:
            obj = target(p)
            b = bounds.get(type(obj))
            if b is not None and _SHORT[0] <= fifo <= _SHORT[1]:
                got = _pt_target(session, profile, name, (profile, p, fifo))
                if got is not None:
                    ctl, bank, pl = got
                    try:
                        v = on_row(pl, lambda: pl.space(fifo))
                    except Exception:
                        v = None
                    if v is not None and b[0] <= v <= b[1]:
                        obj.value = v
                        if bank is not None:
                            bank.streamed_calls += 1
                        return _done(session, ctl, name, advance)
        return slow(*(a for a in args if a is not _NO), *extra, **kw)

    return gt


def fast_move_absolute(
    name: str, slow: Callable[..., int], session: Any, advance: Callable[[Any, str, int], int]
) -> Callable[..., int]:
    """``GT_MoveAbsolute(profile, &prm)``, ``prm`` a TMoveAbsolutePrm passed by ``byref`` or
    itself, on an axis in Trap mode: on the row the bank keeps (a new target in place:
    :func:`gtecat.controller.bank_stream.retarget`) or on an axis it does not run."""
    from ..controller.bank_stream import retarget
    from .fast import _target
    from .plcopen_calls import TMoveAbsolutePrm, move_absolute

    target = _target(frozenset({TMoveAbsolutePrm}))
    trap = PrfMode.TRAP

    def gt(profile: Any = _NO, p: Any = _NO, /, *extra: Any, **kw: Any) -> int:
        if not extra and not kw and type(profile) is int and session.plain:
            obj = target(p)
            ctl = session.controllers.get(1)
            if (
                type(obj) is TMoveAbsolutePrm
                and ctl is not None
                and ctl.clock._thread is None
                and ctl.card is None
            ):
                res = getattr(ctl, "resources", {}).get(profile)
                if res is not None and ctl.axes.get(profile) is res.ax and res.profile.mode is trap:
                    bank = ctl.bank
                    try:
                        if bank is None:
                            move_absolute(ctl, profile, obj)
                            return _done(session, ctl, name, advance)
                        r = stream_row(bank, ctl, name, (profile, p))
                        if r >= 0:
                            retarget(bank, r, lambda: move_absolute(ctl, profile, obj))
                            return _done(session, ctl, name, advance)
                    except Exception:
                        pass  # (refused, nothing changed: the table path says why)
        return slow(*(a for a in (profile, p) if a is not _NO), *extra, **kw)

    return gt


#: function -> the maker of its fast path (the GT layer puts it in front of the table path)
STREAM_MAKERS: dict[str, Callable[..., Callable[..., int]]] = {
    "GT_PtData": fast_pt_data,
    "GT_PtSpace": fast_pt_space,
    "GT_MoveAbsolute": fast_move_absolute,
}

__all__ = ["STREAM_MAKERS", "fast_move_absolute", "fast_pt_data", "fast_pt_space"]
