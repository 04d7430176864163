"""A tap on the GT call stream: every ``gt.GT_*`` / ``GTN_*`` / ``GTE_*`` call an application
makes, with its arguments, what it wrote back and its return code.

:func:`tap` replaces the functions of ``gtecat.gt`` by wrappers that call the listeners
(recordings, :mod:`.record`; application checks, :mod:`.checks`) before and after the call;
:func:`untap` puts them back.  Code that looks the functions up at call time
(``gt.GT_GetSts(...)``, the manual's style) is seen; a name imported before the tap
(``from gtecat.gt import GT_GetSts``) is not.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

#: helpers that return Python objects, not codes: not part of the stream
SKIP = frozenset(
    {
        "GTE_GetLastError",
        "GTE_Controller",
        "GTE_Slave",
        "GTE_GetCycleStats",
        "GTE_ExtModule",
        "GTE_GLinkSlave",
    }
)
_PKG = str(Path(__file__).resolve().parents[1])


class Listener:
    def before(self, name: str, args: tuple, kwargs: dict) -> Any:
        return None

    def after(self, name: str, args: tuple, kwargs: dict, rc: Any, token: Any) -> None:
        pass


_listeners: list[Listener] = []
_saved: dict[str, Callable[..., Any]] = {}
#: per thread: inside a call (a GT call made by another, a motion program's: not the app's)
_inside = threading.local()
#: the application's calls one at a time, whichever thread makes them, so that the order the
#: listeners see (a recording's) is the order they ran in and a replay in one thread gives the
#: same results; a real controller takes one call at a time too
_SERIAL = threading.RLock()
#: calls that let time pass: on the realtime clock they sleep on the wall clock, and holding
#: the other threads' calls for that long would change the program (its replay is not exact
#: anyway: its wall clock decided the order)
_WAITS = frozenset({"GTE_Wait"})


def _waits_on_the_wall(name: str) -> bool:
    if name not in _WAITS:
        return False
    from ..gt._core import SESSION
    from ..master.clock import ClockMode

    ctl = SESSION.controllers.get(1)
    return ctl is not None and ctl.clock.mode is ClockMode.REALTIME


def call_site() -> tuple[str, int]:
    """The first frame outside gtecat: the application's file and line."""
    f = sys._getframe(1)
    while f is not None:
        fn = f.f_code.co_filename
        if not fn.startswith(_PKG) and "runpy" not in fn and not fn.startswith("<frozen"):
            return fn, f.f_lineno
        f = f.f_back  # type: ignore[assignment]
    return "?", 0


def _wrap(name: str, fn: Callable[..., Any]) -> Callable[..., Any]:
    def tapped(*args: Any, **kwargs: Any) -> Any:
        if getattr(_inside, "now", False):  # a GT call made inside another: not the app's
            return fn(*args, **kwargs)
        if _waits_on_the_wall(name):
            return heard(args, kwargs)
        with _SERIAL:
            return heard(args, kwargs)

    def heard(args: tuple, kwargs: dict) -> Any:
        tokens = [lst.before(name, args, kwargs) for lst in _listeners]
        _inside.now = True
        try:
            rc = fn(*args, **kwargs)
        finally:
            _inside.now = False
        for lst, tok in zip(_listeners, tokens, strict=True):
            lst.after(name, args, kwargs, rc, tok)
        return rc

    tapped.__name__ = name
    tapped.__doc__ = fn.__doc__
    tapped.__wrapped__ = fn  # type: ignore[attr-defined]
    tapped.tap_of = fn  # type: ignore[attr-defined]  # (what a motion program calls instead)
    for attr in ("prototype", "__signature__"):
        if hasattr(fn, attr):
            setattr(tapped, attr, getattr(fn, attr))
    return tapped


def tap(listener: Listener) -> None:
    """Listen to the GT calls: ``gtecat.gt``'s functions and the registry a controller process
    dispatches its clients' calls through (``gtecat controller``, libgts programs)."""
    from .. import gt
    from ..gt import _core

    if not _saved:
        for name, fn in list(gt._whole().items()):
            if name.startswith(("GT_", "GTN_", "GTE_")) and callable(fn) and name not in SKIP:
                if isinstance(fn, type):
                    continue
                _saved[name] = fn
                wrapped = _wrap(name, fn)
                setattr(gt, name, wrapped)
                if _core.REGISTRY.get(name) is fn:
                    _core.REGISTRY[name] = wrapped
        _core.TAPPED = True  # a controller's fast answers would pass by: it takes the calls
    _listeners.append(listener)


def untap(listener: Listener) -> None:
    from .. import gt
    from ..gt import _core

    if listener in _listeners:
        _listeners.remove(listener)
    if not _listeners and _saved:
        for name, fn in _saved.items():
            if getattr(_core.REGISTRY.get(name), "__wrapped__", None) is fn:
                _core.REGISTRY[name] = fn
            setattr(gt, name, fn)
        _saved.clear()
        _core.TAPPED = False


__all__ = ["Listener", "call_site", "tap", "untap"]
