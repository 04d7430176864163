"""``GT_HomeSts`` on the fast path: the older cards' homing loop polls it for every axis.

``GT_Home`` runs on the axis's smart homing (:mod:`gtecat.gt.legacy_home_calls`), and
``GT_HomeSts`` gives 1 once that homing ended at its target, 0 while it runs or when none
ran; a failed homing returns 1 with its reason.  The table path checks and converts its
arguments generically (a few microseconds a call, 64 axes polled every 20 ms: a third of a
whole homing's CPU); this function answers the common shapes from the homing's status
directly, as the table path does, and hands every other case to it (:mod:`gtecat.gt.fast`
for the shapes and the session's checks, ``fast_home_status`` for the same homing's
``THomeStatus``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

#: the function this module makes fast
HOME_STS = "GT_HomeSts"


def fast_home_sts(
    name: str,
    slow: Callable[..., int],
    session: Any,
    advance: Callable[[Any, str, int], int],
) -> Callable[..., int]:
    """``GT_HomeSts(axis, p)`` with the fast path in front of the table: ``p`` a ``byref``
    (no offset) or the object itself of an integer type the pointer takes, or an array of
    one (its first element), an axis of the in-process controller (no pulse card) whose
    smart homing the table path or a homing call made before.  A failed homing (1 and its
    reason), a homing not made yet, any other shape: the table path.  (GTN_HomeSts with
    core 1, or of a core viewing core 1's bus, takes this path through the GT layer's twin.)"""
    from ..controller import smart_home as sh
    from .args import _scalar_types
    from .fast import (
        _LOCKSTEP,
        _NO,
        _array_first,
        _int_bounds,
        _target,
        _value_target,
        smart_home_lookup,
    )
    from .table import FUNCTIONS

    ok = _scalar_types(FUNCTIONS[name].params[1])
    bounds = _int_bounds(ok)
    target = _target(ok)
    first = _array_first(ok)
    end = sh.Stage.END
    home_of, _ = smart_home_lookup()

    def gt(n: Any = _NO, p: Any = _NO, /, *extra: Any, **kw: Any) -> int:
        if type(n) is int and not kw and not extra:
            obj, arr = _value_target(p, target, ok, first)
            ctl = None if obj is None else session.controllers.get(1)
            if ctl is not None and session.plain and ctl.clock._thread is None:
                home = home_of(ctl, n)
                if home is not None:
                    st = home.status
                    if st.run or not st.error:  # (a failed homing: 1 and its reason)
                        v = int(not st.run and st.stage == end)
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


__all__ = ["HOME_STS", "fast_home_sts"]
