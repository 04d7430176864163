"""The one function table: every GT function's C prototype and pointer contract.

The table is a package of group files (:mod:`gtecat.gt.groups`): each module there holds
``NAME`` (a short id), ``TITLE`` (words) and ``PROTOTYPES``; adding a group is adding a
file.  A function is *emulated* when the GT layer registers an implementation
(``@gt_function``), else *declared* only (:func:`declared_only`).

Each line of a group's ``PROTOTYPES`` is a prototype as the vendor header writes it (``short`` return,
``long`` stays ``long``, C++ default arguments), followed by the manual's
chapter-13 entry.  A comment after a parameter states what C cannot say:

* ``in`` / ``out`` / ``inout`` with an element count in brackets: a number, the
  name of another parameter (``out[count]``, ``in[size]``), default ``[1]``;
  ``[?]`` when only the call knows (it checks the room itself);
  a pointer without a word is ``out`` (``const`` makes it ``in``);
* ``opt``: the pointer may be NULL (``None``, ``0``, a NULL ctypes pointer) -
  a ``=NULL`` default says the same;
* ``str``: a NUL-terminated text (``char *`` in), ``outstr[n]``: text the
  function writes, at most ``n`` bytes with the NUL;
* ``mask``: a ``long`` bit mask (0 .. 2^32-1 accepted as well as negative longs);
* ``lo..hi``: the legal range of a scalar (beyond the C type's own range).

``short GTN_x(...);`` names a function the vendor DLL exports whose parameters no public
header gives: it is declared only, exported by the library, and left out of ``gts.h``.

Everything that handles arguments reads this table: the Python wrappers'
checks (:mod:`gtecat.gt.args`), and the generated ``gts.h`` and C client stubs
of the native library.  A ``GT_x`` line gives ``GTN_x(short core, ...)`` too;
``GTE_`` lines are the emulator's own functions (no ``GTN_`` twin).
``long`` is the vendor's 32-bit Windows ``long``: values are checked to 32 bits.

A ``GTN_x`` line of its own declares a function of the vendor's GTN header that has no
``GT_x`` line, or whose parameters differ from ``short core`` + those of ``GT_x`` (then
the ``GT_x`` line gives no twin).  ``T **p`` (``char **pVersion``), ``void *`` and
array parameters (``short axis[8]``: a pointer to 8) are read as the vendor writes them.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

#: C scalar types: (ctypes name, lo, hi, is_float); ``long`` is the vendor's 32-bit long
SCALARS: dict[str, tuple[str, int, int, bool]] = {
    "char": ("c_char", -128, 127, False),
    "unsigned char": ("c_ubyte", 0, 0xFF, False),
    "short": ("c_short", -(1 << 15), (1 << 15) - 1, False),
    "unsigned short": ("c_ushort", 0, 0xFFFF, False),
    "int": ("c_int", -(1 << 31), (1 << 31) - 1, False),
    "long": ("c_long", -(1 << 31), (1 << 31) - 1, False),
    "unsigned long": ("c_ulong", 0, (1 << 32) - 1, False),
    "double": ("c_double", 0, 0, True),
    "signed char": ("c_byte", -128, 127, False),
    "unsigned int": ("c_uint", 0, (1 << 32) - 1, False),
    "float": ("c_float", 0, 0, True),
    "long long": ("c_longlong", -(1 << 63), (1 << 63) - 1, False),
    "unsigned long long": ("c_ulonglong", 0, (1 << 64) - 1, False),
    "__int64": ("c_longlong", -(1 << 63), (1 << 63) - 1, False),
    "int64_t": ("c_longlong", -(1 << 63), (1 << 63) - 1, False),
    "int32_t": ("c_int", -(1 << 31), (1 << 31) - 1, False),
    "uint32_t": ("c_uint", 0, (1 << 32) - 1, False),
    "int16_t": ("c_short", -(1 << 15), (1 << 15) - 1, False),
    "uint16_t": ("c_ushort", 0, 0xFFFF, False),
    "uint8_t": ("c_ubyte", 0, 0xFF, False),
}

#: scalar types that are a C enum of a group's ``STRUCTS`` (an ``int`` on the wire)
ENUMS: set[str] = set()


@dataclass(frozen=True, slots=True)
class Param:
    """One parameter of a prototype."""

    name: str
    ctype: str  #: base C type without ``*`` / ``const`` ("unsigned long", "TTrapPrm")
    pointer: bool = False
    direction: str = "in"  #: "in" | "out" | "inout" (scalars are "in")
    count: int | str = 1  #: elements behind the pointer: a number or another parameter's name
    optional: bool = False  #: pointer may be NULL
    text: bool = False  #: NUL-terminated text (``str`` / ``outstr``)
    mask: bool = False
    lo: float | None = None
    hi: float | None = None
    default: str | None = None  #: the C++ default as written ("1", "NULL", "-1")
    comment: str = ""  #: the annotation as written, for the header
    stars: int = 1  #: ``2`` for ``char **pVersion`` (pointers only)

    @property
    def is_float(self) -> bool:
        return not self.pointer and self.ctype in ("double", "float")

    @property
    def is_struct(self) -> bool:
        return self.ctype not in SCALARS and self.ctype not in ENUMS and self.ctype != "void"

    def c_decl(self) -> str:
        """``const char *pFile`` / ``short axis`` / ``char **pVersion``."""
        ctype = f"const {self.ctype}" if self.text and self.direction == "in" else self.ctype
        if self.pointer:
            return f"{ctype} {'*' * self.stars}{self.name}"
        return f"{ctype} {self.name}"

    def default_value(self) -> int | float | None:
        """The default as a Python value (``NULL`` -> None); KeyError when there is none."""
        if self.default is None:
            raise KeyError(self.name)
        if self.default == "NULL":
            return None
        return float(self.default) if self.is_float else int(self.default, 0)


#: ``GT_x`` lines whose ``GTN_x`` twin has no core, as the vendor's GTN header declares
#: them: ``GTN_Open(short channel=5, short param=1)`` and ``GTN_Close(void)`` open and
#: close the whole controller (every core); their parameters with the vendor defaults
NO_CORE_TWINS: dict[str, tuple[tuple[str, str], ...]] = {
    "GT_Open": (("channel", "5"), ("param", "1")),
    "GT_Close": (),
}

#: ``GT_x`` lines whose ``GTN_x`` twin takes the very same parameters (no core), as the
#: vendor's GTN header declares them: the motion-program compiler runs on the host
SAME_PARAM_TWINS: frozenset[str] = frozenset({"GT_Compile", "GT_GetFunId", "GT_GetVarId"})


@dataclass(frozen=True, slots=True)
class Proto:
    """One GT function as the table declares it."""

    name: str
    params: tuple[Param, ...]
    entry: str = ""  #: the manual's chapter-13 entry (or "header")
    core_first_form: bool = False  #: the manual also prints it with the core first (5.2.2.5)
    by_name: dict[str, Param] = field(default_factory=dict, compare=False, repr=False)
    group: str = ""  #: the NAME of the group file that declares it
    twin: bool = True  #: a ``GT_x`` line gives ``GTN_x`` (False: a ``GTN_x`` line of its own)
    #: ``short GTN_x(...);``: the vendor DLL exports the name but no public header gives its
    #: parameters (declared only; not in gts.h; the library exports it)
    unknown: bool = False

    @property
    def gtn(self) -> bool:
        return self.twin and self.name.startswith("GT_")

    @property
    def twin_name(self) -> str:
        return "GTN_" + self.name[3:]

    def c_signature(self, *, defaults: bool, core: bool = False) -> str:
        """The prototype for ``gts.h`` (``core``: the ``GTN_`` twin).

        An input text (``str``) is ``const char *`` where the vendor writes ``char *``: the
        same ABI, and C++ callers passing a string literal (``GT_LoadConfig("GTS800.cfg")``,
        a user's C++ homing program) compile without ISO C++'s string-constant warning."""
        name = ("GTN_" + self.name[3:]) if core else self.name
        if core and self.name in NO_CORE_TWINS:
            own = [
                f"short {n}={d}" if defaults else f"short {n}" for n, d in NO_CORE_TWINS[self.name]
            ]
            return f"short {name}({', '.join(own) or 'void'})"
        parts = ["short core"] if core and self.name not in SAME_PARAM_TWINS else []
        for p in self.params:
            s = p.c_decl()
            if defaults and p.default is not None:
                s += f"={p.default}"
            parts.append(s)
        return f"short {name}({', '.join(parts)})"


_LINE = re.compile(r"^short\s+(\w+)\s*\((.*)\)\s*;\s*(?://\s*(.*))?$")
_PARAM = re.compile(
    r"^(?P<const>const\s+)?(?P<type>(?:(?:unsigned|signed)\s+)?(?:long\s+long|\w+))\s*"
    r"(?P<ptr>\*{0,2})\s*(?P<name>\w+)\s*(?:\[(?P<dim>\d*)\])?"
    r"\s*(?:=\s*(?P<default>[\w.+-]+))?\s*(?:/\*(?P<note>[^*]*)\*/)?$"
)
_COUNT = re.compile(r"^(in|out|inout|outstr)(?:\[(\w+|\?)\])?$")
_RANGE = re.compile(r"^(-?[\d.]+)\.\.(-?[\d.]+)$")
_SPACES = re.compile(r"\s+")


def _param(text: str, where: str) -> Param:
    m = _PARAM.match(_SPACES.sub(" ", text.strip()))
    if not m:
        raise ValueError(f"{where}: cannot read parameter {text!r}")
    ctype = _SPACES.sub(" ", m["type"])
    stars = len(m["ptr"])
    dim = m["dim"]
    pointer = stars > 0 or dim is not None
    note = (m["note"] or "").split()
    kw: dict = {"default": m["default"], "comment": m["note"] or ""}
    if pointer:
        kw["direction"] = "in" if m["const"] else "out"
        kw["optional"] = m["default"] in ("NULL", "0") and stars > 0
        kw["stars"] = max(stars, 1)
        if dim:  # short axis[8]: a pointer to 8
            kw["count"] = int(dim)
        if stars > 1 or ctype == "void":
            kw["count"] = 0  # what a T ** or a void * holds only the call knows
    for word in note:
        if c := _COUNT.match(word):
            kind, count = c.groups()
            kw["direction"] = "out" if kind == "outstr" else kind
            kw["text"] = kind == "outstr"
            if count is not None:
                kw["count"] = 0 if count == "?" else int(count) if count.isdigit() else count
        elif word == "opt":
            kw["optional"] = True
        elif word == "str":
            kw["text"], kw["direction"] = True, "in"
        elif word == "mask":
            kw["mask"] = True
        elif r := _RANGE.match(word):
            kw["lo"], kw["hi"] = float(r[1]), float(r[2])
        else:
            raise ValueError(f"{where}: unknown annotation {word!r}")
    if not pointer and ctype not in SCALARS and ctype not in ENUMS and not ctype.startswith("T"):
        raise ValueError(f"{where}: scalar type {ctype!r} unknown")  # T...: a structure by value
    return Param(m["name"], ctype, pointer, **kw)


#: a parameter's text -> its Param: the ~10,000 parameters of the table are ~2,200 texts
#: (``short axis`` alone hundreds of times), and Param is immutable, so each is read once
_PARAMS: dict[str, Param] = {}


def _param_once(text: str, where: str) -> Param:
    p = _PARAMS[text] = _param(text, where)
    return p


def parse(text: str, group: str = "") -> dict[str, Proto]:
    """The prototypes of ``text`` by name (ValueError names the line it cannot read)."""
    out: dict[str, Proto] = {}
    where = f"group {group}, line" if group else "table line"
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line or line.startswith("//"):
            continue
        m = _LINE.match(line)
        if not m:
            raise ValueError(f"{where} {lineno}: not a prototype: {line!r}")
        name, args, comment = m[1], m[2].strip(), (m[3] or "").strip()
        if args == "void":
            args = ""
        if args == "...":
            if name in out:
                raise ValueError(f"{where} {lineno}: {name} declared twice")
            out[name] = Proto(name, (), entry=comment, group=group, twin=False, unknown=True)
            continue
        params = tuple(
            _PARAMS.get(a) or _param_once(a, f"{where} {lineno} ({name})")
            for a in _split(args)
            if a.strip()
        )
        names = {p.name for p in params}
        for p in params:
            if isinstance(p.count, str) and p.count not in names:
                raise ValueError(f"{where} {lineno}: {p.name} counts by unknown {p.count!r}")
        if len(names) != len(params):
            raise ValueError(f"{where} {lineno}: {name} names a parameter twice")
        if name in out:
            raise ValueError(f"{where} {lineno}: {name} declared twice")
        out[name] = Proto(
            name,
            params,
            entry=comment,
            core_first_form="core first" in comment,
            by_name={p.name: p for p in params},
            group=group,
            # the vendor's GT_x that take the core themselves (GT_SetCore(short core)) have
            # no GTN_x twin
            twin=not (params and params[0].name == "core"),
        )
    for name in out:  # GT_x beside a GTN_x line of its own: no twin
        if name.startswith("GTN_") and "GT_" + name[4:] in out:
            out["GT_" + name[4:]] = _replace_twin(out["GT_" + name[4:]])
    return out


_COMMENT = re.compile(r"/\*.*?\*/", re.S)


def _split(args: str) -> list[str]:
    """Split a parameter list at commas outside comments."""
    if "/*" not in args:
        return args.split(",")
    comments = _COMMENT.findall(args)
    parts = _COMMENT.sub("\0", args).split(",")
    if not comments:
        return parts
    out, it = [], iter(comments)
    for part in parts:
        out.append(re.sub("\0", lambda _: next(it), part))
    return out


def collect(groups: Iterable) -> dict[str, Proto]:
    """Every group's prototypes in one table (:mod:`gtecat.gt.groups` gives the groups).

    A name that two groups declare is an error naming both, except that a *vendor*
    group (``DECLARED_ONLY = True``: the vendor header's declarations, read by
    ``tools/gts_header_table.py``) yields to a group that owns the function: the owner's
    line is the one followed.  A ``GTN_x`` line of its own takes the twin of ``GT_x``.
    """
    out: dict[str, Proto] = {}
    owner: dict[str, object] = {}
    twins: dict[str, Proto] = {}  #: GTN_x -> the GT_x line that gives it, as lines arrive
    vendor: list[tuple[object, dict[str, Proto]]] = []
    for g in groups:
        table = parse(g.prototypes, g.name)
        if g.declared_only:
            vendor.append((g, table))
            continue
        _merge(out, owner, twins, g, table, yield_to_owner=False)
    for g, table in vendor:
        _merge(out, owner, twins, g, table, yield_to_owner=True)
    for name in list(out):
        if name.startswith("GTN_") and ("GT_" + name[4:]) in out:
            gt = out["GT_" + name[4:]]
            if gt.gtn:
                out[gt.name] = _replace_twin(gt)
    return out


def _replace_twin(p: Proto) -> Proto:
    return Proto(p.name, p.params, p.entry, p.core_first_form, p.by_name, p.group, False, p.unknown)


def _merge(
    out: dict, owner: dict, twins: dict, g, table: dict[str, Proto], *, yield_to_owner: bool
) -> None:
    # (a group's own GT_x and GTN_x lines give no twin: parse() said so, twins has none)
    for name, proto in table.items():
        taken = owner.get(name)
        if taken is None and name.startswith("GTN_") and name in twins:
            taken = owner.get(twins[name].name)  # the GT_x line of another group gives it
        if taken is None and proto.gtn and proto.twin_name in out:
            taken = owner.get(proto.twin_name)
        if taken is not None:
            if yield_to_owner and not taken.declared_only:
                continue
            raise ValueError(
                f"{name} is declared in two groups: {taken.name} "
                f"({taken.module}) and {g.name} ({g.module}); delete one of the lines"
            )
        out[name] = proto
        owner[name] = g
        if proto.gtn:
            twins[proto.twin_name] = proto


def _load() -> tuple[tuple, dict[str, Proto]]:
    from . import groups as _groups
    from .typedefs import enum_names

    found = _groups.groups()
    key = _cache_key(found)
    CACHE_KEY[:] = [key]
    cached = _read_cache(key)
    if cached is not None:
        enums, table = cached
        ENUMS.update(enums)
        return found, table
    ENUMS.update(enum_names(found))
    table = collect(found)
    _write_cache(key, table)
    return found, table


# --- the parsed table, kept between processes ---------------------------------------------
# Reading the ~3,700 lines of the groups is most of what importing gtecat.gt costs beyond its
# modules' code (every process pays it: a replay, a test worker, a native client's
# controller).  The table read once is kept in gtecat's per-user cache folder as plain
# values (marshal), named by the digest of everything it is read from: every group's text,
# and the source of this module and of typedefs (the readers).  A changed group is a new
# name; a file that is missing, unreadable or not of the expected shape is read again from
# the groups.  ``GTECAT_PYC_CACHE=0`` turns it off, with gtecat's bytecode cache.


def _cache_key(found: Iterable) -> str | None:
    import hashlib
    import os
    import sys

    if os.environ.get("GTECAT_PYC_CACHE", "1") == "0":
        return None
    h = hashlib.sha256(f"{sys.version}\0{_CACHE_FORMAT}\0".encode())
    try:
        from . import typedefs

        for mod in (sys.modules[__name__], typedefs):
            with open(mod.__file__, "rb") as f:
                h.update(f.read())
    except (OSError, TypeError, KeyError):
        return None
    for g in found:
        for part in (
            g.name,
            g.module,
            str(g.declared_only),
            g.prototypes,
            g.structs,
            g.constants,
        ):
            h.update(part.encode("utf-8", "surrogatepass"))
            h.update(b"\0")
    return h.hexdigest()[:32]


#: the shape of the cached values (raised when it changes)
_CACHE_FORMAT = 1
#: the key the groups were read under (None: the cache is off); the vendor surface's plain
#: values are kept under it too (:func:`gtecat.gt.typedefs.surface`)
CACHE_KEY: list[str | None] = [None]


def _cache_file(key: str, kind: str = "functions"):
    from .. import __version__
    from .._cache import cache_root

    return cache_root() / __version__ / "table" / f"{kind}-{key}.marshal"


def _read_cache(key: str | None) -> tuple[list[str], dict[str, Proto]] | None:
    import marshal

    if key is None:
        return None
    try:
        enums, params, protos = marshal.loads(_cache_file(key).read_bytes())
        param, proto = _filler(Param), _filler(Proto)
        made = [param(*p) for p in params]
        out: dict[str, Proto] = {}
        for name, idx, entry, core_first, group, twin, unknown in protos:
            ps = tuple([made[i] for i in idx])
            out[name] = proto(
                name, ps, entry, core_first, {p.name: p for p in ps}, group, twin, unknown
            )
        return list(enums), out
    except Exception:  # (missing, unreadable, another shape: read from the groups)
        return None


def _filler(cls: type) -> Any:
    """``cls(*values)`` for a frozen slotted dataclass, its values in field order and known
    good (written by :func:`_write_cache`): each slot set by its own descriptor instead of the
    frozen ``__init__``'s ``object.__setattr__`` a field (the table's ~5,600 objects read
    back in ~8 ms instead of ~13)."""
    slots = cls.__slots__
    body = "".join(f"    _set_{f}(o, {f})\n" for f in slots)
    source = f"def fill({', '.join(slots)}):\n    o = _new(_cls)\n{body}    return o\n"
    ns: dict[str, Any] = {"_new": object.__new__, "_cls": cls}
    ns.update((f"_set_{f}", cls.__dict__[f].__set__) for f in slots)
    exec(compile(source, f"<{cls.__name__} read back>", "exec"), ns)
    return ns["fill"]


def _write_cache(key: str | None, table: dict[str, Proto]) -> None:
    import marshal
    import os

    if key is None:
        return
    index: dict[int, int] = {}  # id(Param) -> its place
    params: list[tuple] = []
    protos = []
    for p in table.values():
        idx = []
        for q in p.params:
            k = index.get(id(q))
            if k is None:
                k = index[id(q)] = len(params)
                params.append(tuple(getattr(q, f) for f in Param.__slots__))
            idx.append(k)
        protos.append((p.name, tuple(idx), p.entry, p.core_first_form, p.group, p.twin, p.unknown))
    try:
        path = _cache_file(key)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        tmp.write_bytes(marshal.dumps((sorted(ENUMS), params, protos)))
        os.replace(tmp, path)
    except (OSError, ValueError, RuntimeError):
        pass  # a read-only home, or none: read from the groups again next time


#: every group of the table (:class:`gtecat.gt.groups.Group`), in file-name order
GROUPS, FUNCTIONS = _load()
#: the table's text, every group's lines in group order (the protocol digest reads it)
PROTOTYPES: str = "\n".join(f"// group {g.name}\n{g.prototypes}" for g in GROUPS)
_GROUP_BY_NAME = {g.name: g for g in GROUPS}


def group_of(name: str):
    """The group that declares ``name`` (``GT_x``, its ``GTN_x`` twin, ``GTE_x``)."""
    proto = FUNCTIONS.get(name)
    if proto is None and name.startswith("GTN_"):
        proto = FUNCTIONS.get("GT_" + name[4:])
    if proto is None:
        raise KeyError(name)
    return _GROUP_BY_NAME[proto.group]


def emulated() -> frozenset[str]:
    """The table's names (``GT_x``/``GTE_x`` lines) that the GT layer implements."""
    from . import REGISTRY  # importing gtecat.gt registers every @gt_function

    return frozenset(n for n in FUNCTIONS if n in REGISTRY)


def declared_only() -> tuple[str, ...]:
    """The table's names that no implementation registers: calling one returns
    :data:`gtecat.gt._core.CMD_DECLARED` with a reason."""
    done = emulated()
    return tuple(n for n in FUNCTIONS if n not in done)


def exported_names() -> list[str]:
    """Every function name the table gives the native library (``GT_x``, its twin)."""
    out = []
    for p in FUNCTIONS.values():
        out.append(p.name)
        if p.gtn:
            out.append(p.twin_name)
    return out


__all__ = [
    "ENUMS",
    "FUNCTIONS",
    "GROUPS",
    "NO_CORE_TWINS",
    "PROTOTYPES",
    "SAME_PARAM_TWINS",
    "SCALARS",
    "Param",
    "Proto",
    "collect",
    "declared_only",
    "emulated",
    "exported_names",
    "group_of",
    "parse",
]
