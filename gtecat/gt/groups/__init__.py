"""The function table, one file per group of functions.

Every module of this package is a group: it holds

* ``NAME`` - a short id (``"ext_io"``), used by ``gtecat api --group`` and the reference pages;
* ``TITLE`` - what the group is, in words (``"extension IO modules"``), used in messages
  such as "GT_SetHSIOOpt is declared but not emulated (group: high-speed IO)";
* ``PROTOTYPES`` - the group's prototypes, one a line, in the table's syntax
  (:mod:`gtecat.gt.table` describes it);

and may hold

* ``STRUCTS`` - C ``typedef struct`` / ``union`` / ``enum`` text of the structures its
  prototypes use (:mod:`gtecat.gt.typedefs` reads it; a structure ``gtecat.gt`` already
  defines as a ctypes class keeps that definition);
* ``CONSTANTS`` - ``#define NAME value`` lines (numbers only);
* ``DECLARED_ONLY = True`` - the group lists the vendor header's declarations (read by
  ``tools/gts_header_table.py``); a function another group also declares belongs to
  that group.

Adding a group is adding a file here; nothing else names the groups.
"""

from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Group:
    name: str
    title: str
    module: str  #: ``gtecat.gt.groups.<file>``
    prototypes: str
    structs: str = ""
    constants: str = ""
    declared_only: bool = False
    doc: str = ""


def groups() -> tuple[Group, ...]:
    """Every group module of this package, in file-name order (ValueError on a bad one)."""
    out: list[Group] = []
    names: dict[str, str] = {}
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        if info.name.startswith("_"):
            continue
        mod = importlib.import_module(f"{__name__}.{info.name}")
        where = mod.__name__
        try:
            name, title, protos = mod.NAME, mod.TITLE, mod.PROTOTYPES
        except AttributeError as e:
            raise ValueError(
                f"{where}: a group module needs NAME, TITLE and PROTOTYPES ({e})"
            ) from None
        if not (isinstance(name, str) and name.isidentifier()):
            raise ValueError(f"{where}: NAME must be a short identifier, not {name!r}")
        if name in names:
            raise ValueError(f"group {name!r} is defined twice: {names[name]} and {where}")
        names[name] = where
        out.append(
            Group(
                name,
                str(title),
                where,
                str(protos),
                structs=str(getattr(mod, "STRUCTS", "")),
                constants=str(getattr(mod, "CONSTANTS", "")),
                declared_only=bool(getattr(mod, "DECLARED_ONLY", False)),
                doc=(mod.__doc__ or "").strip(),
            )
        )
    return tuple(out)


__all__ = ["Group", "groups"]
