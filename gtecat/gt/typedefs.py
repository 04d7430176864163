"""The vendor's structures, unions, enums and constants, from the groups' C text.

A group module (:mod:`gtecat.gt.groups`) may carry ``STRUCTS``, C typedefs as the vendor
header writes them::

    typedef struct { double kp; long integralLimit; short limit; } TPid;
    typedef union { TResetIo resetIo; double data[7]; } TResetModePrmUnion;
    typedef enum { TIME_ELAPSE_PROFILE = 1000, TIME_ELAPSE_SCAN = 18000 } ETimeElapse;

and ``CONSTANTS``, ``#define NAME value`` lines.  This module reads both and builds
ctypes classes with the vendor's layout: ``long`` is the vendor's 32-bit Windows ``long``
(``c_int32``), pointers are ``c_void_p``, an enum is an ``int``.  ``gtecat.gt`` exports
them beside its own hand-written structures (which win where both define a name), and
``gts.h`` writes them back field by field (:mod:`gtecat.native.cdecl`).
"""

from __future__ import annotations

import ctypes
import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

#: C field types -> ctypes, the vendor's (Windows) sizes
FIELD_TYPES: dict[str, Any] = {
    "char": ctypes.c_char,
    "signed char": ctypes.c_byte,
    "unsigned char": ctypes.c_ubyte,
    "short": ctypes.c_short,
    "unsigned short": ctypes.c_ushort,
    "int": ctypes.c_int32,
    "unsigned int": ctypes.c_uint32,
    "unsigned": ctypes.c_uint32,
    "long": ctypes.c_int32,
    "unsigned long": ctypes.c_uint32,
    "long long": ctypes.c_int64,
    "unsigned long long": ctypes.c_uint64,
    "__int64": ctypes.c_int64,
    "int64_t": ctypes.c_int64,
    "uint64_t": ctypes.c_uint64,
    "int32_t": ctypes.c_int32,
    "uint32_t": ctypes.c_uint32,
    "int16_t": ctypes.c_int16,
    "uint16_t": ctypes.c_uint16,
    "int8_t": ctypes.c_int8,
    "uint8_t": ctypes.c_uint8,
    "float": ctypes.c_float,
    "double": ctypes.c_double,
    "bool": ctypes.c_bool,
    # the Windows names the headers use (windows.h: 32-bit LONG/DWORD)
    "BOOL": ctypes.c_int32,
    "BYTE": ctypes.c_ubyte,
    "UCHAR": ctypes.c_ubyte,
    "WORD": ctypes.c_ushort,
    "USHORT": ctypes.c_ushort,
    "SHORT": ctypes.c_short,
    "DWORD": ctypes.c_uint32,
    "UINT": ctypes.c_uint32,
    "INT": ctypes.c_int32,
    "LONG": ctypes.c_int32,
    "ULONG": ctypes.c_uint32,
    "INT8": ctypes.c_int8,
    "UINT8": ctypes.c_uint8,
    "INT16": ctypes.c_int16,
    "UINT16": ctypes.c_uint16,
    "INT32": ctypes.c_int32,
    "UINT32": ctypes.c_uint32,
}


class TypedefError(ValueError):
    """C text this reader cannot turn into a layout (it names the typedef)."""


@dataclass(frozen=True, slots=True)
class Field:
    ctype: str
    name: str
    dims: tuple[int, ...] = ()
    pointer: bool = False


@dataclass(frozen=True, slots=True)
class Typedef:
    kind: str  #: "struct" | "union" | "enum"
    name: str
    fields: tuple[Field, ...] = ()
    members: tuple[tuple[str, int], ...] = ()  #: enum members and their values
    group: str = ""


_COMMENT = re.compile(r"/\*.*?\*/|//[^\n]*", re.S)
_TYPEDEF = re.compile(
    r"typedef\s+(struct|union|enum)\s*(\w+)?\s*\{(?P<body>[^{}]*)\}\s*(?P<names>[^;]*);", re.S
)
_FIELD = re.compile(
    r"^(?:const\s+)?(?:struct\s+)?(?P<type>(?:(?:unsigned|signed)\s+)?(?:long\s+long|\w+))"
    r"\s*(?P<rest>.+)$",
    re.S,
)
_DECL = re.compile(r"^(?P<ptr>\*?)\s*(?P<name>\w+)\s*(?P<dims>(?:\[\s*\w*\s*\]\s*)*)$")
_DEFINE = re.compile(r"^\s*#\s*define\s+(\w+)\s+(.+?)\s*$", re.M)


def strip_comments(text: str) -> str:
    return _COMMENT.sub(" ", text)


#: a plain decimal (no leading zero: C reads 010 as octal) or hexadecimal integer
_PLAIN = re.compile(r"-?(?:0[xX][0-9a-fA-F]+|[1-9][0-9]*|0)")


def number(text: str, known: dict[str, int] | None = None) -> int | float | None:
    """A C constant expression of the simple kinds headers use (``(-6)``, ``0x100``,
    ``1<<3``, ``(MC_AXIS+1)``, ``1.5``), None when it is something else."""
    t = text.strip()
    if _PLAIN.fullmatch(t):  # most are: enum values, array sizes
        return int(t, 0)
    t = re.sub(r"(?<=[0-9a-fA-FxX])[uUlL]+\b", "", t)
    if not t or not re.fullmatch(r"[\w\s()+\-*/<>|&~.^]+", t):
        return None
    names = set(re.findall(r"[A-Za-z_]\w*", re.sub(r"\b0[xX][0-9a-fA-F]+\b", "0", t)))
    env: dict[str, Any] = {}
    for n in names:
        if known is None or n not in known:
            return None
        env[n] = known[n]
    try:
        v = eval(t, {"__builtins__": {}}, env)
    except Exception:
        return None
    if isinstance(v, bool) or not isinstance(v, int | float):
        return None
    return v


def parse_constants(text: str, known: dict[str, int] | None = None) -> dict[str, int | float]:
    """``#define NAME value`` lines whose value is a number, in order."""
    out: dict[str, int | float] = {}
    env = dict(known or {})
    for m in _DEFINE.finditer(strip_comments(text)):
        v = number(m[2], env)
        if v is not None:
            out[m[1]] = env[m[1]] = v
    return out


#: (text, group) -> its typedefs, read without ``known``: the table reads every group's
#: STRUCTS for its enum names and ``gtecat.gt`` again for its classes, once per process
_PARSED: dict[tuple[str, str], tuple[Typedef, ...]] = {}


def parse(text: str, group: str = "", known: dict[str, Any] | None = None) -> list[Typedef]:
    """The typedefs of ``text`` in order (TypedefError names what it cannot read);
    ``known``: constants an array size may name."""
    if known is None:
        if (text, group) not in _PARSED:
            _PARSED[text, group] = tuple(_parse(text, group, None))
        return list(_PARSED[text, group])
    return _parse(text, group, known)


def _parse(text: str, group: str, known: dict[str, Any] | None) -> list[Typedef]:
    out: list[Typedef] = []
    for m in _TYPEDEF.finditer(strip_comments(text)):
        kind, body = m[1], m["body"]
        names = [n.strip() for n in m["names"].split(",")]
        name = names[0]
        if not name.isidentifier():
            raise TypedefError(f"typedef {kind} {m[2] or ''}: cannot read the name {name!r}")
        if kind == "enum":
            out.append(Typedef(kind, name, members=_enum(body, name), group=group))
        else:
            out.append(Typedef(kind, name, fields=_fields(body, name, known), group=group))
    return out


def _enum(body: str, where: str) -> tuple[tuple[str, int], ...]:
    members: list[tuple[str, int]] = []
    known: dict[str, int] = {}
    nxt = 0
    for part in body.split(","):
        part = part.strip()
        if not part:
            continue
        n, _, v = part.partition("=")
        n = n.strip()
        if v.strip():
            val = number(v, known)
            if not isinstance(val, int):
                raise TypedefError(f"{where}: enum value {part!r}")
            nxt = val
        members.append((n, nxt))
        known[n] = nxt
        nxt += 1
    return tuple(members)


def _fields(body: str, where: str, known: dict[str, Any] | None) -> tuple[Field, ...]:
    out: list[Field] = []
    for decl in body.split(";"):
        decl = " ".join(decl.split())
        if not decl:
            continue
        m = _FIELD.match(decl)
        if not m:
            raise TypedefError(f"{where}: cannot read field {decl!r}")
        ctype = m["type"]
        for one in m["rest"].split(","):
            d = _DECL.match(one.strip().replace("* ", "*"))
            if not d or ":" in one:
                raise TypedefError(f"{where}: cannot read field {decl!r}")
            dims = []
            for x in re.findall(r"\[\s*(\w+)\s*\]", d["dims"]):
                n = number(x, known)
                if not isinstance(n, int) or n <= 0:
                    raise TypedefError(f"{where}: array size {x!r} of {d['name']}")
                dims.append(n)
            out.append(Field(ctype, d["name"], tuple(dims), bool(d["ptr"])))
    return out


@dataclass
class Built:
    """The ctypes classes of every group's typedefs, and the enum members."""

    classes: dict[str, Any] = field(default_factory=dict)
    enums: dict[str, Typedef] = field(default_factory=dict)
    typedefs: dict[str, Typedef] = field(default_factory=dict)


def __getattr__(name: str) -> Any:
    # ``BUILT``: what :func:`build` made of every group (the classes are those ``gtecat.gt``
    # made when it was imported: :func:`gtecat.gt.vendor.built`), made when first asked for
    if name == "BUILT":
        from .vendor import built

        globals()["BUILT"] = made = built()
        return made
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def build(typedefs: Iterable[Typedef], existing: dict[str, Any]) -> Built:
    """ctypes classes for ``typedefs`` (a name in ``existing`` keeps that class; a later
    duplicate of a name already read is skipped: the first group's reading wins)."""
    out = Built()
    pending = []
    for td in typedefs:
        if td.name in out.typedefs:
            continue
        out.typedefs[td.name] = td
        if td.kind == "enum":
            out.enums[td.name] = td
        elif td.name not in existing:
            pending.append(td)
    classes = dict(existing)
    progress = True
    while pending and progress:  # nested structures first
        progress = False
        for td in list(pending):
            try:
                cls = _make(td, classes, out.enums)
            except KeyError:
                continue
            classes[td.name] = out.classes[td.name] = cls
            pending.remove(td)
            progress = True
    if pending:
        td = pending[0]
        missing = [
            f.ctype
            for f in td.fields
            if f.ctype not in FIELD_TYPES and f.ctype not in classes and f.ctype not in out.enums
        ]
        raise TypedefError(f"{td.name}: unknown field type(s) {', '.join(missing)}")
    return out


def _make(td: Typedef, classes: dict[str, Any], enums: dict[str, Typedef]) -> Any:
    fields = []
    for f in td.fields:
        if f.pointer:
            t: Any = ctypes.c_void_p
        elif f.ctype in FIELD_TYPES:
            t = FIELD_TYPES[f.ctype]
        elif f.ctype in enums:
            t = ctypes.c_int32
        else:
            t = classes[f.ctype]  # KeyError: not built yet
        for d in reversed(f.dims):
            t = t * d
        fields.append((f.name, t))
    base = ctypes.Union if td.kind == "union" else ctypes.Structure
    doc = f"``{td.name}`` as the vendor header lays it out (group {td.group})."
    return type(td.name, (base,), {"_fields_": fields, "__doc__": doc})


def enum_names(groups: Iterable[Any]) -> set[str]:
    """The enum type names the groups' ``STRUCTS`` define (scalar parameter types)."""
    out: set[str] = set()
    for g in groups:  # (the bodies are read when gtecat.gt makes its vendor surface)
        for m in _TYPEDEF.finditer(strip_comments(g.structs)):
            if m[1] == "enum":
                out.add(m["names"].split(",")[0].strip())
    return out


# --- every group's typedefs and defines as plain values, kept between processes ---------------
# ``gtecat.gt`` makes its vendor surface (the groups' classes, enum members and constants) when
# it is imported.  Reading the groups' C text for it costs ~25 ms a process; the values read
# are kept as plain values (marshal) beside the function table, under the table's name (its key
# covers every group's text and the source of this module): read back in ~2 ms.

#: a typedef as plain values: (kind, name, group, fields, members), a field (ctype, name, dims,
#: pointer), a member (name, value)
RawTypedef = tuple[str, str, str, tuple[tuple[str, str, tuple[int, ...], bool], ...], tuple]
#: a ``#define``: (name, value, expression); value None where the expression names other
#: constants (evaluated against them when the surface is made: :func:`number`)
RawDefine = tuple[str, "int | float | None", str]


def surface(
    groups: Iterable[Any], *, kept: bool = True
) -> tuple[tuple[RawTypedef, ...], tuple[tuple[RawDefine, ...], ...]]:
    """Every group's typedefs (in group order, as :func:`parse` reads them) and its
    ``#define`` lines (one tuple per group) as plain values, from the cache when it holds
    them (:data:`gtecat.gt.table.CACHE_KEY`; ``kept`` False: read from the groups, and kept
    again)."""
    import marshal

    from .table import CACHE_KEY, _cache_file

    key = CACHE_KEY[0]
    if key is not None and kept:
        try:
            tds, defines = marshal.loads(_cache_file(key, "surface").read_bytes())
            if type(tds) is tuple and type(defines) is tuple:
                return tds, defines
        except Exception:  # (missing, unreadable, another shape: read from the groups)
            pass
    groups = tuple(groups)
    tds = tuple(
        (
            td.kind,
            td.name,
            td.group,
            tuple((f.ctype, f.name, f.dims, f.pointer) for f in td.fields),
            td.members,
        )
        for g in groups
        for td in parse(g.structs, g.name)
    )
    defines = tuple(_defines(g.constants) for g in groups)
    if key is not None:
        _keep(_cache_file(key, "surface"), (tds, defines))
    return tds, defines


def _defines(text: str) -> tuple[RawDefine, ...]:
    return tuple((m[1], number(m[2], {}), m[2]) for m in _DEFINE.finditer(strip_comments(text)))


def _keep(path: Any, values: Any) -> None:
    import marshal
    import os

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        tmp.write_bytes(marshal.dumps(values))
        os.replace(tmp, path)
    except (OSError, ValueError):
        pass  # a read-only home, or none: read from the groups again next time


def enum_decl(td: Typedef) -> str:
    """``typedef enum ETimeElapse { ... } ETimeElapse;`` for ``gts.h``."""
    body = ",\n".join(f"    {n} = {v}" for n, v in td.members)
    return f"typedef enum {td.name} {{\n{body}\n}} {td.name};"


__all__ = [
    "Built",
    "Field",
    "Typedef",
    "TypedefError",
    "build",
    "enum_decl",
    "enum_names",
    "number",
    "parse",
    "parse_constants",
    "strip_comments",
    "surface",
]
