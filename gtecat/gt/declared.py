"""Functions the table declares but gtecat does not emulate.

Every name of the vendor's public headers is in the function table (:mod:`gtecat.gt.groups`),
so an application finds every function it calls.  Those without an implementation
(no ``@gt_function``) are *declared only*: called from Python, through libgts or from
C#, they do nothing and return :data:`~gtecat.gt._core.CMD_DECLARED` (8, the vendor's
``CMD_ERROR_UNKNOWN``) whatever the arguments (they are not looked at: the same code on
every face), leave the reason for ``GTE_GetLastError``
("GT_SetHSIOOpt is declared but not emulated (group: high-speed IO)") and write one line
per function to the master log of the open controller.  They never return 0.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from . import _core
from .table import Proto, group_of


def reason(name: str) -> str:
    """Why ``name`` returns :data:`~gtecat.gt._core.CMD_DECLARED`."""
    try:
        title = group_of(name).title
    except (KeyError, StopIteration):
        title = "none"
    return f"{name} is declared but not emulated (group: {title})"


def note(name: str) -> tuple[int, str]:
    """Record a declared-only call of ``name``: the master-log line (once per function and
    controller), the last error; returns (code, reason)."""
    text = reason(name)
    ctl = _core.SESSION.controllers.get(1)
    if ctl is not None:
        logged = ctl.__dict__.setdefault("_declared_logged", set())
        if name not in logged:
            logged.add(name)
            ctl.log(f"{text}: it returns {_core.CMD_DECLARED} (CMD_ERROR_UNKNOWN)")
        ctl.clock.on_call()
    _core._record(name, _core.CMD_DECLARED, text)
    return _core.CMD_DECLARED, text


def declared_function(proto: Proto) -> list[Callable[..., int]]:
    """``GT_x`` (and its ``GTN_x`` twin) for a declared-only table line."""

    def make(name: str, signature: str) -> Callable[..., int]:
        def fn(*args: Any, **kwargs: Any) -> int:
            return note(name)[0]

        fn.__name__ = fn.__qualname__ = name
        fn.__doc__ = (
            f"``{signature}`` - {reason(name)}: returns {_core.CMD_DECLARED} "
            "(CMD_ERROR_UNKNOWN) whatever the arguments."
        )
        fn.prototype = proto  # type: ignore[attr-defined]
        fn.declared = True  # type: ignore[attr-defined]
        return fn

    out = [make(proto.name, proto.c_signature(defaults=True))]
    if proto.gtn:
        out.append(make(proto.twin_name, proto.c_signature(defaults=True, core=True)))
    return out


__all__ = ["declared_function", "note", "reason"]
