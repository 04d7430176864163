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
    from .fast import smart_home_lookup, status_reader
    from .table import FUNCTIONS

    end = sh.Stage.END
    home_of, _ = smart_home_lookup()

    def status(n: int) -> tuple[Any, int] | None:
        """(the controller, 1 once axis ``n``'s homing ended at its target, 0 while it runs or
        when none ran) where the fast path answers it, else None: no controller in this
        process, a homing not made yet, a failed homing (1 with its reason)."""
        ctl = session.controllers.get(1)
        if ctl is None or not session.plain or ctl.clock._thread is not None:
            return None
        home = home_of(ctl, n)
        if home is None:
            return None
        st = home.status
        if st.run or not st.error:
            return ctl, int(not st.run and st.stage == end)
        return None

    ok = _scalar_types(FUNCTIONS[name].params[1])
    return status_reader(name, slow, session, advance, status, ok)


__all__ = ["HOME_STS", "fast_home_sts"]
