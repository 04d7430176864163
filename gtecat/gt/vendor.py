"""The vendor surface of :mod:`gtecat.gt`: every name of the vendor's headers that no module of
the GT layer defines, put into its namespace when it is imported.

* the groups' structures and unions (:mod:`gtecat.gt.typedefs`; a structure a module of
  ``gtecat.gt`` defines keeps that class);
* the members of the groups' enums and their ``#define`` constants (a name ``gtecat.gt``
  already holds keeps its value);
* for every declared-only line of the function table, ``GT_x`` and its ``GTN_x`` twin: a
  :class:`~gtecat.gt.declared.DeclaredFunction` (it returns the declared code with a reason).

Every name is in the namespace from the import on, so the module needs no ``__getattr__``:
CPython specialises the loads of a module's attributes only while it has none
(``gt.GT_GetSts`` ~11 ns a load, ~30 ns with one).  What would cost is kept cheap: the
groups' C text is read once and kept (:func:`gtecat.gt.typedefs.surface`), and a
declared-only function is only its name until its docstring, signature or table line is
asked for.  Most of what remains is making the ~600 ctypes classes.
"""

from __future__ import annotations

import ctypes
from collections import ChainMap
from collections.abc import Iterator, Mapping
from typing import Any

from . import typedefs
from .declared import DeclaredFunction
from .table import FUNCTIONS, GROUPS


def is_public(name: str, value: object) -> bool:
    """What the stable surface exports: functions, structures, constants (DESIGN.md)."""
    if name.startswith("_"):
        return False
    if name.startswith(("GT_", "GTN_", "GTE_")):
        return True
    if name.startswith("T") and isinstance(value, type) and issubclass(value, ctypes.Structure):
        return True  # TTrapPrm, TJogPrm, TSlaveInfo ...
    return name.isupper() and len(name) > 1 and isinstance(value, int | float | str)


#: the classes :func:`install` made (the plain values it read them from are not kept: ~1 MB,
#: read again by :func:`built`)
_MADE: dict[str, type] = {}


def install(g: dict[str, Any], registry: Mapping[str, object]) -> None:
    """Put the vendor surface into the namespace ``g`` (``gtecat.gt``'s), whose own modules'
    names and ``registry`` (the emulated functions) are in it already."""
    try:
        _install(g, registry, typedefs.surface(GROUPS))
    except Exception:  # kept values of another shape (a damaged file): read from the groups
        _install(g, registry, typedefs.surface(GROUPS, kept=False))


def _install(g: dict[str, Any], registry: Mapping[str, object], surface: Any) -> None:
    tds, defines = surface
    made, enums = _classes(tds, g)
    for name, cls in made.items():
        g.setdefault(name, cls)
    members: set[str] = set()
    for td in enums:
        for member, value in td[4]:
            if member not in g:
                g[member] = value
                members.add(member)
    _constants(defines, g, members)
    for name, proto in FUNCTIONS.items():
        if name not in registry:
            g[name] = DeclaredFunction(name)
            if proto.gtn:
                g[proto.twin_name] = DeclaredFunction(proto.twin_name)
    _MADE.clear()
    _MADE.update(made)


def _existing(g: dict[str, Any], name: str) -> Any:
    """The class ``gtecat.gt``'s own modules give ``name``, else None."""
    v = g.get(name)
    return v if isinstance(v, type) and is_public(name, v) else None


def _classes(
    tds: tuple[typedefs.RawTypedef, ...], g: dict[str, Any]
) -> tuple[dict[str, type], list[typedefs.RawTypedef]]:
    """The ctypes classes of the typedefs that ``g`` has no class for, in the order
    :func:`gtecat.gt.typedefs.build` makes them (nested structures first; the first reading
    of a name wins), and the enums."""
    seen: set[str] = set()
    enums: list[typedefs.RawTypedef] = []
    enum_names: set[str] = set()
    pending: list[typedefs.RawTypedef] = []
    for td in tds:
        name = td[1]
        if name in seen:
            continue
        seen.add(name)
        if td[0] == "enum":
            enums.append(td)
            enum_names.add(name)
        elif _existing(g, name) is None:
            pending.append(td)
    made: dict[str, type] = {}
    types = typedefs.FIELD_TYPES
    int32, void_p = ctypes.c_int32, ctypes.c_void_p
    struct, union = ctypes.Structure, ctypes.Union
    while pending:
        rest = []
        for td in pending:
            kind, name, group, raw_fields, _ = td
            fields = []
            for ctype, fname, dims, pointer in raw_fields:
                if pointer:
                    t: Any = void_p
                elif ctype in types:
                    t = types[ctype]
                elif ctype in enum_names:
                    t = int32
                else:
                    t = made.get(ctype) or _existing(g, ctype)
                    if t is None:
                        break  # a structure not made yet
                for d in reversed(dims):
                    t = t * d
                fields.append((fname, t))
            else:
                base = union if kind == "union" else struct
                made[name] = type(base)(
                    name,
                    (base,),
                    {
                        "_fields_": fields,
                        "__doc__": f"``{name}`` as the vendor header lays it out (group {group}).",
                        "__module__": "gtecat.gt",
                    },
                )
                continue
            rest.append(td)
        if len(rest) == len(pending):
            td = rest[0]
            missing = [
                f[0]
                for f in td[3]
                if not f[3]
                and f[0] not in types
                and f[0] not in enum_names
                and f[0] not in made
                and _existing(g, f[0]) is None
            ]
            raise typedefs.TypedefError(f"{td[1]}: unknown field type(s) {', '.join(missing)}")
        pending = rest
    return made, enums


class _Known(Mapping[str, Any]):
    """The constants a ``#define`` may name: ``g``'s public integers less the enum members
    the surface added, and the constants it added."""

    def __init__(self, g: dict[str, Any], hidden: set[str], added: dict[str, Any]) -> None:
        self.g, self.hidden, self.added = g, hidden, added

    def __contains__(self, name: object) -> bool:
        if name in self.added:
            return True
        v = self.g.get(name, self)  # type: ignore[call-overload]
        return (
            v is not self and name not in self.hidden and isinstance(v, int) and is_public(name, v)  # type: ignore[arg-type]
        )

    def __getitem__(self, name: str) -> Any:
        if name in self.added:
            return self.added[name]
        if name not in self:
            raise KeyError(name)
        return self.g[name]

    def __iter__(self) -> Iterator[str]:  # (not walked: number() only asks for names)
        return iter(())

    def __len__(self) -> int:
        return 0


def _constants(
    defines: tuple[tuple[typedefs.RawDefine, ...], ...], g: dict[str, Any], members: set[str]
) -> None:
    """Each group's ``#define``s that ``g`` does not hold, in order (an expression may name a
    constant ``gtecat.gt`` defines, one of an earlier group or of its own)."""
    added: dict[str, Any] = {}
    known = _Known(g, members, added)
    for group in defines:
        own: dict[str, Any] = {}
        for name, value, expr in group:
            if value is None:
                value = typedefs.number(expr, ChainMap(own, known))  # type: ignore[arg-type]
                if value is None:
                    continue
            own[name] = value
        for name, value in own.items():
            if name not in g:
                g[name] = added[name] = value


def built() -> typedefs.Built:
    """What :func:`gtecat.gt.typedefs.build` makes of every group, with the classes that
    ``gtecat.gt`` holds (made when it was imported)."""
    from .. import gt  # noqa: F401  (its import made them)

    out = typedefs.Built(classes=dict(_MADE))
    for kind, name, group, fields, members in typedefs.surface(GROUPS)[0]:
        if name in out.typedefs:
            continue
        td = typedefs.Typedef(kind, name, tuple(typedefs.Field(*f) for f in fields), members, group)
        out.typedefs[name] = td
        if kind == "enum":
            out.enums[name] = td
    return out


__all__ = ["DeclaredFunction", "built", "install", "is_public"]
