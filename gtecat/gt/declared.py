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

import types
from typing import Any

from . import _core
from .table import FUNCTIONS, Proto, group_of


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


def _any_arguments(*args: Any, **kwargs: Any) -> int:
    """(the signature every declared-only function shows: it takes anything)"""
    return _core.CMD_DECLARED


#: the signature every declared-only function shows (made once, when first asked for)
_SIGNATURE: list[Any] = []


class DeclaredFunction:
    """``GT_x`` (or its ``GTN_x`` twin) of a declared-only table line, as ``gtecat.gt`` holds it.

    ``gtecat.gt`` puts one in its namespace for each of the ~3,800 declared-only names when
    it is imported (no module ``__getattr__``: CPython specialises the loads of a module's
    attributes only while it has none), so each is only its name until more is asked for:
    its table line (:attr:`prototype`), docstring and signature are made from the table when
    read.  Called, it returns :data:`~gtecat.gt._core.CMD_DECLARED` with its reason whatever
    the arguments.  Otherwise it is used as the Python function it stands for: pickled and
    copied as itself (by its name), weakly referenced, bound as a method where a class holds
    it (so ``inspect.isroutine`` and pydoc take it for a function), given attributes.
    """

    __slots__ = ("__dict__", "__name__", "__qualname__", "__weakref__")
    declared = True

    def __init__(self, name: str) -> None:
        self.__name__ = self.__qualname__ = name

    def __call__(self, *args: Any, **kwargs: Any) -> int:
        return note(self.__name__)[0]

    @property
    def prototype(self) -> Proto:
        """The table line: ``GT_x``'s for ``GT_x`` and for its ``GTN_x`` twin."""
        name = self.__name__
        proto = FUNCTIONS.get(name)
        if proto is None and name.startswith("GTN_"):
            proto = FUNCTIONS.get("GT_" + name[4:])
        if proto is None:
            raise AttributeError(f"{name} has no line in the function table")
        return proto

    def _doc(self) -> str:
        proto = self.prototype
        twin = self.__name__ != proto.name
        return (
            f"``{proto.c_signature(defaults=True, core=twin)}`` - {reason(self.__name__)}: "
            f"returns {_core.CMD_DECLARED} (CMD_ERROR_UNKNOWN) whatever the arguments."
        )

    @property
    def __signature__(self) -> Any:
        if not _SIGNATURE:
            import inspect

            _SIGNATURE.append(inspect.signature(_any_arguments))
        return _SIGNATURE[0]

    def __get__(self, obj: Any, cls: Any = None) -> Any:
        return self if obj is None else types.MethodType(self, obj)

    def __reduce__(self) -> tuple[Any, tuple[str]]:
        return by_name, (self.__name__,)

    def __copy__(self) -> DeclaredFunction:
        return self

    def __deepcopy__(self, memo: Any) -> DeclaredFunction:
        return self

    def __repr__(self) -> str:
        return f"<GT function {self.__name__} (declared only)>"


class _Doc:
    """``__doc__``: the class's own text on the class, the function's (made when read) on
    one of its objects."""

    def __init__(self, text: str | None) -> None:
        self.text = text

    def __get__(self, obj: Any, cls: Any = None) -> str | None:
        return self.text if obj is None else obj._doc()


DeclaredFunction.__doc__ = _Doc(DeclaredFunction.__doc__)  # type: ignore[assignment]


def by_name(name: str) -> Any:
    """The public GT function ``name`` (how a pickled one comes back: itself)."""
    from .. import gt

    return getattr(gt, name)


def declared_function(proto: Proto) -> list[DeclaredFunction]:
    """``GT_x`` (and its ``GTN_x`` twin) for a declared-only table line."""
    out = [DeclaredFunction(proto.name)]
    if proto.gtn:
        out.append(DeclaredFunction(proto.twin_name))
    return out


__all__ = ["DeclaredFunction", "by_name", "declared_function", "note", "reason"]
