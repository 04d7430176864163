"""Turn vendor GT headers into candidate function-table groups (a maintainer tool).

    python tools/gts_header_table.py gts.h [more headers...]            # print a summary
    python tools/gts_header_table.py --out gtecat/gt/groups gts.h ...  # write vendor_*.py
    python tools/gts_header_table.py --only-missing --out gtecat/gt/groups gts.h gxn.cs ...

Reads the ``GT_API`` prototypes, ``typedef struct/union/enum`` blocks and numeric
``#define`` constants of the headers the maintainer names (GBK or UTF-8, as they ship) and
writes them in the table's syntax as *declared-only* group modules
(``DECLARED_ONLY = True``): ``vendor_<topic>.py`` per topic, ``vendor_types.py`` with the
structures and constants.  Where headers disagree the first header named wins, so name the
newest first.  A ``GTN_x`` equal to ``short core`` + ``GT_x`` becomes one ``GT_x`` line
(the table gives the twin); otherwise both lines are written.  A header whose functions
take ``short cardNum`` first (the older multi-card GTS ABI) gives its functions without
that parameter, after every other header (``gtecat lib --abi gts-multicard`` puts it
back).  Comments of the headers are not carried over.  A newer header's ``int16_t``,
``uint32_t``, ``__int64`` ... are written as the table spells them (``short``, ``unsigned
int``, ``long long``), C++ ``bool`` as ``unsigned char``, a function pointer spelled in place
as ``void *``, bit-fields of one type as the whole units they fill (``unsigned short
bits1;``); a function taking by value a structure the table cannot name (not ``T...``) is
left out with a line on stderr.

A C# wrapper (``*.cs``: ``[DllImport("gts.dll")] public static extern short GT_x(...)``,
``public const short NAME = value;``, ``public struct TName { ... }``) is read as a header
of the GTN era: C# ``short``/``ushort``/``int``/``uint``/``long``/``ulong`` are the vendor's
``short``/``unsigned short``/``long``/``unsigned long``/``long long``/``unsigned long long``
(its 32-bit Windows ``long``), ``out T`` a pointer it writes, ``ref T`` and ``T[]`` pointers
it reads and writes (``[?]``: only the call knows how many), ``string`` a text, ``IntPtr`` a
``void *``.  A function whose C# form takes a structure by value, or a type the table cannot
name, is left out with a line on stderr.

``--dll-exports`` names what a vendor DLL exports (``objdump -p gxn.dll``); a name no
header declares becomes ``short NAME(...);``: exported by libgts, declared only, not in
``gts.h``.

``--only-missing`` keeps what the function table (every group file of ``--out``, but
this mode's own ``vendor_gtn_*`` files) lacks, and writes it as ``vendor_gtn_<topic>.py``
groups and ``vendor_gtn_types.py`` (structures and constants the table lacks): run it after
the vendor groups, naming the newer headers and wrappers; a function the table has (itself,
or as the ``GTN_x`` twin of a ``GT_x``) is not repeated, whatever parameters the newer header
gives it (the table's line is the one the field was checked against; a header that declares
it otherwise is named on stderr).  ``--add`` keeps the ``vendor_gtn_*`` lines an earlier run
wrote (they count as the table) and adds what they lack, so a newer header can be read on its
own; a ``(...)`` line it gives a prototype for gives way.

    python tools/gts_header_table.py --only-missing --add --out gtecat/gt/groups newer.h
"""

from __future__ import annotations

import argparse
import re
import sys
from collections import defaultdict
from pathlib import Path


def _typedefs():
    """gtecat/gt/typedefs.py on its own: importing gtecat.gt would load the table this
    tool may be rewriting."""
    import importlib.util

    path = Path(__file__).resolve().parents[1] / "gtecat" / "gt" / "typedefs.py"
    spec = importlib.util.spec_from_file_location("_gt_typedefs", path)
    mod = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    sys.modules[spec.name] = mod  # type: ignore[union-attr]
    spec.loader.exec_module(mod)  # type: ignore[union-attr]
    return mod


typedefs = _typedefs()

_API = re.compile(r"\bGT_API\s+(\w+)\s*\(([^;]*?)\)\s*;", re.S)
_PARAM = re.compile(
    r"^(?P<const>const\s+)?(?:struct\s+)?(?P<type>(?:(?:unsigned|signed)\s+)?(?:long\s+long|\w+))"
    r"\s*(?P<ptr>[*&]*)\s*(?P<name>\w+)?\s*(?P<dim>\[\s*\d*\s*\])?\s*(?:=\s*(?P<default>[^,]+))?$"
)

#: (topic, title, name pattern) in order: the first match files a function
TOPICS: tuple[tuple[str, str, str], ...] = (
    ("ethercat", "EtherCAT", r"Ecat|Sdo|Pdo"),
    ("ringnet", "ring net, GSN and terminals", r"RingNet|^RN_|Terminal|Gsn|GLink|NetInit|Net_"),
    ("ext_io", "extension IO modules", r"Ext(Mdl|Io|Do|Di|Ad|Da|Module)|ExtMdl"),
    ("compare", "position compare and triggers", r"Compare|Trigger|Pso|Laser"),
    ("look_ahead", "look-ahead and buffered interpolation commands", r"LookAhead|^Buf|CrdData"),
    ("crd", "coordinated motion", r"Crd|^Ln|^Arc|^Helix|^Ln|Circle|Spline|Path"),
    ("pvt", "PT, PVT, gear, follow and cam", r"Pvt|^Pt|^Prf|Gear|Follow|Cam"),
    ("plcopen", "PLCopen-style moves", r"^Move|Group|Synchron"),
    (
        "servo",
        "servo loop, pulse output and analog",
        r"Pid|Dac|Adc|Step|Pulse|Ctrl|Control|Kvff|Filter|Sense|Sns|Encoder|Enc[A-Z]|Mpg|Hand",
    ),
    ("homing", "homing and capture", r"Home|Capture|Index"),
    (
        "compensation",
        "compensation, gantry and kinematics",
        r"Compensat|LeadScrew|Gantry|Backlash|Transform|Kinematic|Robot|Tool|Coord",
    ),
    (
        "programs",
        "programs, variables, watch and scan",
        r"Thread|Var|Compile|Download|Fun|Watch|Scan|Dlm|Bind|Plc|Event",
    ),
    ("io", "digital and analog IO", r"Di|Do|Gpi|Gpo|Ai|Ao|Io|Hsio|HSIO|Lmt|Limit|Alarm"),
    ("config", "configuration", r"Config|Map|Res|Card|Version|Core"),
    ("basic", "basic functions", r""),
    ("exports", "exported by the vendor DLL, parameters not public", r"(?!)"),
)


def read(path: Path) -> str:
    raw = path.read_bytes()
    for enc in ("utf-8", "gbk"):
        try:
            return raw.decode(enc)
        except UnicodeDecodeError:
            continue
    return raw.decode("latin-1")


#: function-pointer typedefs seen (``typedef short (*TInterruptCallback)(TInterrupt);``):
#: such a parameter is written ``void *``
CALLBACKS: set[str] = set()
_CALLBACK = re.compile(r"typedef\s+[\w\s*]+\(\s*(?:__stdcall\s*)?\*\s*(\w+)\s*\)")


#: the <stdint.h> and Windows spellings a newer header uses, as the table spells them (the
#: header gts.h declares them with no <stdint.h>)
_PLAIN_C = {
    "__int64": "long long", "int64_t": "long long", "uint64_t": "unsigned long long",
    "int32_t": "int", "uint32_t": "unsigned int", "int16_t": "short",
    "uint16_t": "unsigned short", "int8_t": "signed char", "uint8_t": "unsigned char",
}  # fmt: skip


def plain_c(text: str) -> str:
    return re.sub(r"\b(" + "|".join(_PLAIN_C) + r")\b", lambda m: _PLAIN_C[m[1]], text)


_INLINE_CALLBACK = re.compile(
    r"(^|,)\s*[\w\s*]*?\(\s*(?:__stdcall\s*)?\*\s*(\w+)\s*\)\s*\([^()]*\)"
)


def params(text: str, where: str) -> list[str]:
    """The parameters in table syntax (``type *name=default``)."""
    text = " ".join(text.split())
    for cb in (*CALLBACKS, "HANDLE", "LPVOID"):  # a pointer whatever it points to
        text = re.sub(rf"\b{cb}\b\s*", "void *", text)
    # a function-pointer parameter spelled in place (``void (*pfn)(void *, short *)``)
    text = _INLINE_CALLBACK.sub(r"\1 void *\2", text)
    text = re.sub(r"\bbool\b", "unsigned char", text)  # C++'s bool: one byte under MSVC
    text = plain_c(text)
    if text in ("", "void"):
        return []
    out = []
    for i, part in enumerate(text.split(",")):
        m = _PARAM.match(part.strip())
        if not m:
            raise ValueError(f"{where}: cannot read parameter {part!r}")
        ptr = m["ptr"].replace("&", "*")  # a C++ reference travels as a pointer
        name = m["name"] or f"arg{i + 1}"
        s = f"{'const ' if m['const'] else ''}{m['type']} {ptr}{name}"
        if m["dim"]:
            s += m["dim"].replace(" ", "")
        if m["default"]:
            s += "=" + m["default"].strip()
        out.append(s)
    return out


def _types(ps: list[str]) -> list[str]:
    ps = [re.sub(r"/\*.*?\*/", "", p).strip() for p in ps]
    return [re.sub(r"\s*\w+(\[\d*\])?(=.*)?$", "", p) for p in ps]


def topic(name: str) -> str:
    bare = re.sub(r"^GTN?_", "", name)
    for key, _, pattern in TOPICS:
        if re.search(pattern, bare):
            return key
    return "basic"


#: C# parameter and field types -> the table's C types (the vendor's Windows sizes)
CS_TYPES: dict[str, str] = {
    "short": "short",
    "Int16": "short",
    "ushort": "unsigned short",
    "UInt16": "unsigned short",
    "int": "long",
    "Int32": "long",
    "uint": "unsigned long",
    "UInt32": "unsigned long",
    "long": "long long",
    "Int64": "long long",
    "ulong": "unsigned long long",
    "UInt64": "unsigned long long",
    "double": "double",
    "Double": "double",
    "float": "float",
    "Single": "float",
    "byte": "unsigned char",
    "Byte": "unsigned char",
    "sbyte": "signed char",
    "SByte": "signed char",
    "char": "char",  # marshalled as an ANSI byte (CharSet.Ansi, the wrappers' default)
}

#: structure and enum names a C# wrapper declares (``public struct OCA_CTRL_GEN``)
CS_DECLARED: set[str] = set()

_CS_EXTERN = re.compile(
    r"\[\s*DllImport\s*\(\s*\"(?:gts|gxn|gen|gts_rn|gt_rn)\.dll\"[^\]]*\]\s*"
    r"public\s+static\s+extern\s+short\s+(\w+)\s*\(([^)]*)\)\s*;",
    re.S | re.I,
)
_CS_CONST = re.compile(
    r"public\s+const\s+(?:short|ushort|int|uint|long|double|Int16|UInt16|Int32|UInt32)\s+(\w+)"
    r"\s*=\s*(\(?\s*-?\s*(?:0x[0-9a-fA-F]+|[\d.]+)\s*\)?)\s*;"
)
_CS_STRUCT = re.compile(r"public\s+struct\s+(\w+)\s*\{([^{}]*)\}", re.S)
_CS_ENUM = re.compile(r"public\s+enum\s+(\w+)\s*(?::\s*\w+\s*)?\{([^{}]*)\}", re.S)
#: enum names (a C# enum travels as an int)
CS_ENUMS: set[str] = set()
_CS_FIELD = re.compile(
    r"(?:\[\s*MarshalAs\s*\([^\]]*?SizeConst\s*=\s*(?P<size>\d+)[^\]]*\]\s*)?"
    r"public\s+(?P<type>[\w.]+)(?P<arr>\[\])?\s+(?P<names>\w+(?:\s*,\s*\w+)*)\s*;"
)


class CsSkip(ValueError):
    """A C# declaration the table cannot say the same way (left out, with this reason)."""


def _cs_type(t: str) -> str:
    t = t.split(".")[-1]  # GTN.mc.TVersion
    if t in CS_TYPES:
        return CS_TYPES[t]
    if t in CS_DECLARED or (t[:1] in "TE" and (t[1:2].isupper() or t[1:2].isdigit())):
        return t
    raise CsSkip(f"type {t!r}")


def cs_params(text: str) -> list[str]:
    """A C# parameter list in table syntax."""
    # [MarshalAs(...)], [In, Out] go; an array's [] stays
    text = re.sub(r"\[[^\]]*[A-Za-z][^\]]*\]", " ", " ".join(text.split()))
    if not text.strip():
        return []
    out = []
    for i, part in enumerate(text.split(",")):
        m = re.match(
            r"^\s*(?:(?P<mod>out|ref|in|params)\s+)?(?P<type>[\w.]+)\s*(?P<arr>\[\s*\])?\s*(?P<name>\w+)"
            r"\s*(?:=\s*(?P<default>[-\w.]+))?\s*$",
            part,
        )
        if not m:
            raise CsSkip(f"parameter {part.strip()!r}")
        t, mod, name = m["type"].split(".")[-1], m["mod"], m["name"] or f"arg{i + 1}"
        if t in ("string", "String"):
            out.append(f"char *{name} /*str*/" if not mod else f"char *{name} /*outstr[?]*/")
            continue
        if t in ("StringBuilder",):
            out.append(f"char *{name} /*outstr[?]*/")
            continue
        if t in ("IntPtr", "UIntPtr"):
            out.append(f"void *{name}")
            continue
        c = _cs_type(t)
        if m["arr"] or mod == "ref":
            out.append(f"{c} *{name} /*inout[?]*/" if m["arr"] else f"{c} *{name} /*inout*/")
        elif mod == "out":
            out.append(f"{c} *{name}")
        elif c not in CS_TYPES.values() and c not in CS_ENUMS:
            raise CsSkip(f"structure {c} passed by value")
        else:
            d = m["default"]
            out.append(f"{c} {name}" + (f"={d}" if d and re.match(r"^-?[\d.]+$", d) else ""))
    return out


def read_cs(path: Path, text: str) -> tuple[list[tuple[str, list[str]]], dict, list[str]]:
    """A C# wrapper's functions, constants and ``struct`` typedefs (C text)."""
    text = typedefs.strip_comments(text)
    enums = []
    for name, body in _CS_ENUM.findall(text):
        CS_DECLARED.add(name)
        CS_ENUMS.add(name)
        members = [m.strip() for m in body.split(",") if m.strip()]
        enums.append(f"typedef enum {{ {', '.join(members)} }} {name};")
    CS_DECLARED.update(n for n, _ in _CS_STRUCT.findall(text))
    found = []
    for m in _CS_EXTERN.finditer(text):
        try:
            found.append((m[1], cs_params(m[2])))
        except CsSkip as e:
            print(f"{path}: {m[1]} left out: {e}", file=sys.stderr)
    consts: dict[str, int | float] = {}
    for name, value in _CS_CONST.findall(text):
        v = typedefs.number(value.replace(" ", ""))
        if v is not None:
            consts.setdefault(name, v)
    structs = []
    for sm in _CS_STRUCT.finditer(text):
        name, body = sm[1], sm[2]
        kind = "struct"
        if "LayoutKind.Explicit" in text[max(0, sm.start() - 80) : sm.start()]:
            # the C header's union (some wrappers write FieldOffset(1) for its second member,
            # which C# packs at byte 1: a slip of the wrapper, not the vendor's layout)
            kind = "union"
        fields = []
        try:
            for f in _CS_FIELD.finditer(body):
                if f["type"].split(".")[-1] in ("string", "String", "IntPtr"):
                    fields += [f"char *{n.strip()};" for n in f["names"].split(",")]
                    continue
                c = _cs_type(f["type"])
                dim = ""
                if f["arr"]:
                    if not f["size"]:
                        raise CsSkip(f"array {f['names']} without SizeConst")
                    dim = f"[{f['size']}]"
                fields += [f"{c} {n.strip()}{dim};" for n in f["names"].split(",")]
        except CsSkip as e:
            print(f"{path}: struct {name} left out: {e}", file=sys.stderr)
            continue
        if fields:
            structs.append(f"typedef {kind} {{ {' '.join(fields)} }} {name};")
    return found, consts, enums + structs


#: a function's other parameter lists, as later headers or wrappers declare it (the first
#: named wins; its table line says what the others declare)
OTHERS: dict[str, list[str]] = {}


def _plain(ps: list[str]) -> str:
    """The parameter types, as a reader compares them (``short, long *, short``)."""
    return ", ".join(re.sub(r"\s*\*\s*", " *", t).strip() for t in _types(ps))


#: the width in bits of the integer types a bit-field is declared with
_BITS = {
    "char": 8, "unsigned char": 8, "int8_t": 8, "uint8_t": 8,
    "short": 16, "unsigned short": 16, "int16_t": 16, "uint16_t": 16,
    "int": 32, "unsigned int": 32, "long": 32, "unsigned long": 32,
    "int32_t": 32, "uint32_t": 32,
}  # fmt: skip
_BITFIELD = re.compile(r"((?:unsigned\s+)?\w+)\s+\w+\s*:\s*(\d+)\s*;")


def fold_bitfields(block: str) -> str:
    """Bit-fields of one integer type (``unsigned short a : 1; ...``) become the whole
    storage units they fill (``unsigned short bits1;``): the layout MSVC gives them; the
    table names no single bit."""
    fields = list(_BITFIELD.finditer(block))
    if not fields:
        return block
    kinds = {" ".join(m[1].split()) for m in fields}
    if len(kinds) != 1 or next(iter(kinds)) not in _BITS:
        return block  # mixed types: left to the reader, which says it cannot read them
    kind = kinds.pop()
    units, used = 1, 0
    for m in fields:  # a bit-field that does not fit what is left starts the next unit
        if used + int(m[2]) > _BITS[kind]:
            units, used = units + 1, 0
        used += int(m[2])
    unit_fields = " ".join(f"{kind} bits{i + 1};" for i in range(units))
    start, end = fields[0].start(), fields[-1].end()
    if _BITFIELD.sub("", block[start:end]).strip():
        return block  # other fields between the bit-fields
    return block[:start] + unit_fields + block[end:]


def extract(paths: list[Path]) -> tuple[dict[str, list[str]], list, dict]:
    functions: dict[str, list[str]] = {}
    tds: list = []
    consts: dict[str, int | float] = {}
    multi: list[tuple[str, list[str]]] = []

    def take(found: list[tuple[str, list[str]]]) -> None:
        firsts = [ps[0] for n, ps in found if n.startswith("GT_") and ps]
        if firsts and sum("cardNum" in p for p in firsts) > len(firsts) / 2:
            # the multi-card ABI: the same functions with short cardNum first
            multi.extend((n, ps[1:] if ps and "cardNum" in ps[0] else ps) for n, ps in found)
        else:
            for name, ps in found:
                add(name, ps)

    def add(name: str, ps: list[str]) -> None:
        if name not in functions:
            functions[name] = ps
        elif _plain(functions[name]) != _plain(ps) and _plain(ps) not in OTHERS.get(name, []):
            OTHERS.setdefault(name, []).append(_plain(ps))

    for path in paths:
        if path.suffix.lower() == ".cs":
            found_cs, cs_consts, cs_structs = read_cs(path, read(path))
            take(found_cs)
            for k, v in cs_consts.items():
                consts.setdefault(k, v)
            for block in cs_structs:
                try:
                    tds.extend(typedefs.parse(block, known=consts))
                except typedefs.TypedefError as e:
                    print(f"{path}: skipped: {e}", file=sys.stderr)
            continue
        text = typedefs.strip_comments(read(path))
        CALLBACKS.update(_CALLBACK.findall(text))
        take([(m[1], params(m[2], f"{path}:{m[1]}")) for m in _API.finditer(text)])
        for k, v in typedefs.parse_constants(text, consts).items():
            consts.setdefault(k, v)
        body = re.sub(r"^\s*#.*$", "", text, flags=re.M)
        # C++ spells a type without typedef: enum EVelMode { ... };
        body = re.sub(
            r"(?<!typedef )\b(struct|union|enum)\s+(\w+)\s*(\{[^{}]*\})\s*;",
            r"typedef \1 \3 \2;",
            body,
        )
        for block in re.findall(r"typedef\s+(?:struct|union|enum)\s*\w*\s*\{[^{}]*\}[^;]*;", body):
            block = plain_c(fold_bitfields(block))
            try:
                tds.extend(typedefs.parse(block, known=consts))
            except typedefs.TypedefError as e:
                print(f"{path}: skipped: {e}", file=sys.stderr)
    for name, ps in multi:  # after every single-card header: those win
        add(name, ps)
    return functions, tds, consts


def lines(functions: dict[str, list[str]]) -> dict[str, list[str]]:
    by_topic: dict[str, list[str]] = defaultdict(list)
    for name in sorted(functions, key=lambda n: (re.sub(r"^GTN?_", "", n), n)):
        ps = functions[name]
        if name.startswith("GTN_"):
            gt = functions.get("GT_" + name[4:])
            if gt is not None and _types(ps) == ["short", *_types(gt)]:
                continue  # the GT_x line gives it
        line = f"short {name}({', '.join(ps)});"
        others = [o for o in OTHERS.get(name, []) if o != _plain(ps)]
        if others:
            line += "  // header; other public copies declare " + " or ".join(
                f"({o})" for o in others
            )
        by_topic[topic(name)].append(line)
    return by_topic


def render_group(key: str, title: str, protos: list[str]) -> str:
    body = "\n".join(protos)
    return (
        f'"""{title[0].upper() + title[1:]}: declared as the vendor header declares them.\n\n'
        "Generated by tools/gts_header_table.py from the vendor headers; a group that\n"
        'emulates a function declares it itself (that line is followed)."""\n\n'
        f'NAME = "vendor_{key}"\nTITLE = "{title}"\nDECLARED_ONLY = True\n\n'
        f'PROTOTYPES = r"""\n{body}\n"""\n'
    )


def render_struct(td) -> str:
    if td.kind == "enum":
        body = ", ".join(f"{n} = {v}" for n, v in td.members)
        return f"typedef enum {{ {body} }} {td.name};"
    fs = " ".join(
        f"{f.ctype} {'*' if f.pointer else ''}{f.name}{''.join(f'[{d}]' for d in f.dims)};"
        for f in td.fields
    )
    return f"typedef {td.kind} {{ {fs} }} {td.name};"


def _module(path: Path):
    """A group file on its own (plain constants; importing gtecat.gt would load the table)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(f"_group_{path.stem}", path)
    mod = importlib.util.module_from_spec(spec)  # type: ignore[arg-type]
    spec.loader.exec_module(mod)  # type: ignore[union-attr]
    return mod


_HAND_STRUCT = re.compile(r"^class (\w+)\((?:ctypes\.)?(?:Structure|Union)\)", re.M)


#: the parameter types of what the table declares (``table_has`` fills it): a header that
#: declares one of them otherwise is reported, and the table's line is kept
TABLE_PARAMS: dict[str, str] = {}


def table_has(folder: Path, own: bool = False) -> tuple[set[str], set[str], set[str], set[str]]:
    """What the table's group files in ``folder`` declare, but ``vendor_gtn_*`` (unless
    ``own``): function names (with the ``GTN_x`` twins), names declared ``(...)`` only,
    structure/enum names and constants."""
    names: set[str] = set()
    unknown: set[str] = set()
    structs: set[str] = set()
    consts: set[str] = set()
    for path in sorted(folder.glob("*.py")):
        if path.name.startswith("_") or (path.name.startswith("vendor_gtn_") and not own):
            continue
        mod = _module(path)
        for m in re.finditer(r"^short\s+(\w+)\s*\((.*)\)\s*;", mod.PROTOTYPES, re.M):
            name, args = m[1], m[2].strip()
            if args == "...":
                unknown.add(name)
                continue
            names.add(name)
            if args not in ("", "void"):
                ps = [p.strip() for p in re.sub(r"/\*.*?\*/", "", args).split(",")]
                TABLE_PARAMS.setdefault(name, _plain(ps))
            if name.startswith("GT_") and not re.match(r"^short\s+core\b", args):
                names.add("GTN_" + name[3:])
        text = typedefs.strip_comments(getattr(mod, "STRUCTS", ""))
        structs |= set(re.findall(r"\}\s*(\w+)\s*;", text))
        consts |= set(re.findall(r"^\s*#define\s+(\w+)", getattr(mod, "CONSTANTS", ""), re.M))
    for path in folder.parent.glob("*.py"):  # the ctypes classes gtecat.gt writes by hand
        structs |= set(_HAND_STRUCT.findall(path.read_text(encoding="utf-8")))
    return names, unknown, structs, consts


#: macros of C and windows.h that a vendor header defines when its compiler lacks them
C_MACROS = frozenset({"NULL", "TRUE", "FALSE", "true", "false", "EOF", "INFINITE"})


def _table_reads(ctype: str, tds: list) -> bool:
    """Whether the table reads a parameter of this type passed by value: a scalar, an
    enum, or a structure named ``T...``."""
    ctype = re.sub(r"^const\s+", "", ctype).strip()
    if ctype in typedefs.FIELD_TYPES or ctype.startswith("T"):
        return True
    return any(td.name == ctype and td.kind == "enum" for td in tds)


def only_missing(
    folder: Path, functions: dict[str, list[str]], tds: list, consts: dict, own: bool = False
) -> tuple[dict[str, list[str]], list, dict, set[str]]:
    """Keep what the table lacks (with ``own``, the ``vendor_gtn_*`` files count as the
    table); also the ``(...)`` names that now have a prototype."""
    names, unknown, structs, have_consts = table_has(folder, own)
    new: dict[str, list[str]] = {}
    for name, ps in functions.items():
        if name in TABLE_PARAMS and _plain(ps) != TABLE_PARAMS[name]:
            print(
                f"{name}: the table's ({TABLE_PARAMS[name]}) kept; this header declares"
                f" ({_plain(ps)})",
                file=sys.stderr,
            )
        if name in names or not re.match(r"^GTN?_\w+$", name):
            continue
        if odd := [t for t in _types(ps) if "*" not in t and not _table_reads(t, tds)]:
            print(f"{name} left out: a {odd[0]} by value the table cannot name", file=sys.stderr)
            continue
        if name.startswith("GT_") and "GTN_" + name[3:] in names:
            # the table declares the GTN_x on its own: a GT_x line would give a second one
            print(f"{name} left out: the table declares GTN_{name[3:]} itself", file=sys.stderr)
            continue
        new[name] = ps
    for name in list(new):  # a GTN_x that the GT_x line of this run gives
        gt = new.get("GT_" + name[4:]) if name.startswith("GTN_") else None
        if gt is not None and _types(new[name]) == ["short", *_types(gt)]:
            del new[name]
    kept_tds = [td for td in tds if td.name not in structs]
    while True:  # a structure with a field of a type nobody defines is left out
        known = structs | {td.name for td in kept_tds} | set(typedefs.FIELD_TYPES)
        bad = [
            td
            for td in kept_tds
            if td.kind != "enum" and any(f.ctype not in known for f in td.fields)
        ]
        if not bad:
            break
        for td in bad:
            print(f"struct {td.name} left out: a field of an unknown type", file=sys.stderr)
        kept_tds = [td for td in kept_tds if td not in bad]
    kept_consts = {  # not the C library's own macros a header may define for itself
        k: v
        for k, v in consts.items()
        if k not in have_consts and k not in C_MACROS and not k.startswith("_")
    }
    gives = {
        "GTN_" + n[3:]
        for n, ps in new.items()
        if n.startswith("GT_") and not (ps and re.match(r"^short\s+core\b", ps[0]))
    }
    return new, kept_tds, kept_consts, unknown & (set(new) | gives)


def _name(line: str) -> str:
    return re.match(r"short\s+(\w+)", line)[1]  # type: ignore[index]


def _earlier(folder: Path, resolved: set[str]) -> tuple[dict[str, list[str]], list[str], dict]:
    """The lines the ``vendor_gtn_*`` files of an earlier run hold (for ``--add``), but the
    ``(...)`` lines of names that now have a prototype."""
    by_topic: dict[str, list[str]] = {}
    structs: list[str] = []
    consts: dict[str, str] = {}
    for key, _, _ in TOPICS:
        path = folder / f"vendor_gtn_{key}.py"
        if path.exists():
            body = _module(path).PROTOTYPES
            by_topic[key] = [
                ln
                for ln in body.strip().splitlines()
                if ln.strip() and not (ln.endswith("(...);") and _name(ln) in resolved)
            ]
    path = folder / "vendor_gtn_types.py"
    if path.exists():
        mod = _module(path)
        structs = [ln for ln in mod.STRUCTS.strip().splitlines() if ln.strip()]
        for m in re.finditer(r"^#define\s+(\w+)\s+(.*)$", mod.CONSTANTS, re.M):
            consts[m[1]] = m[2]
    return by_topic, structs, consts


def _sort_key(line: str) -> tuple[str, str]:
    name = _name(line)
    return (re.sub(r"^GTN?_", "", name), name)


def write_missing(
    folder: Path,
    by_topic: dict[str, list[str]],
    structs: list[str],
    consts: dict,
    resolved: set[str],
    add: bool = False,
) -> None:
    if add:  # an earlier run's lines stay; this run's join them
        old_topic, old_structs, old_consts = _earlier(folder, resolved)
        by_topic = {
            k: sorted(old_topic.get(k, []) + by_topic.get(k, []), key=_sort_key)
            for k in set(old_topic) | set(by_topic)
        }
        structs = old_structs + structs
        consts = {**old_consts, **consts}
    for old in folder.glob("vendor_gtn_*.py"):
        old.unlink()
    for key, title, _ in TOPICS:
        if by_topic.get(key):
            body = "\n".join(by_topic[key])
            (folder / f"vendor_gtn_{key}.py").write_text(
                f'"""{title[0].upper() + title[1:]}: what newer GTN-era vendor headers, C# '
                "wrappers\nand DLLs declare beyond the vendor groups, as they declare it.\n\n"
                "Generated by tools/gts_header_table.py --only-missing; a group that emulates a\n"
                'function declares it itself (that line is followed)."""\n\n'
                f'NAME = "vendor_gtn_{key}"\nTITLE = "{title} (newer GTN era)"\n'
                f'DECLARED_ONLY = True\n\nPROTOTYPES = r"""\n{body}\n"""\n',
                encoding="utf-8",
            )
    cst = "\n".join(f"#define {k} {v}" for k, v in consts.items())
    st = "\n".join(structs)
    (folder / "vendor_gtn_types.py").write_text(
        '"""Structures, enums and constants of newer GTN-era vendor headers and C# wrappers\n'
        "that the vendor groups lack (no functions).\n\n"
        'Generated by tools/gts_header_table.py --only-missing."""\n\n'
        'NAME = "vendor_gtn_types"\nTITLE = "vendor structures and constants (newer GTN headers)"\n'
        'DECLARED_ONLY = True\nPROTOTYPES = ""\n\n'
        f'STRUCTS = r"""\n{st}\n"""\n\nCONSTANTS = r"""\n{cst}\n"""\n',
        encoding="utf-8",
    )
    exports = folder / "vendor_exports.py"
    if resolved and exports.exists():  # a name with a prototype now leaves the (...) list
        text = exports.read_text(encoding="utf-8")
        for name in resolved:
            text = re.sub(rf"^short {name}\(\.\.\.\);\n", "", text, flags=re.M)
        exports.write_text(text, encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("headers", nargs="+", type=Path)
    ap.add_argument("--out", type=Path, help="write vendor_*.py group modules into this folder")
    ap.add_argument(
        "--dll-exports",
        type=Path,
        help="a list of the names a vendor gts.dll exports (one a line, e.g. from "
        "`objdump -p gts.dll`): those no header declares become `short NAME(...);` lines",
    )
    ap.add_argument(
        "--only-missing",
        action="store_true",
        help="keep what the group files of --out lack; write vendor_gtn_*.py",
    )
    ap.add_argument(
        "--add",
        action="store_true",
        help="with --only-missing: keep the vendor_gtn_*.py lines an earlier run wrote and "
        "add what they lack too (a (...) line gives way to a prototype)",
    )
    args = ap.parse_args(argv)
    functions, tds, consts = extract(args.headers)
    resolved: set[str] = set()
    if args.only_missing:
        if not args.out:
            ap.error("--only-missing needs --out (the folder of the group files)")
        functions, tds, consts, resolved = only_missing(
            args.out, functions, tds, consts, own=args.add
        )
    elif args.add:
        ap.error("--add needs --only-missing")
    by_topic = lines(functions)
    if args.dll_exports:
        have = set(functions)
        have |= {  # the twins the table gives (a GT_x that takes the core itself has none)
            "GTN_" + n[3:]
            for n, ps in functions.items()
            if n.startswith("GT_") and not (ps and re.search(r"\bcore$", ps[0]))
        }
        if args.only_missing:  # and what the table declares, with or without parameters
            table_names, table_unknown, _, _ = table_has(args.out, args.add)
            have |= table_names | (table_unknown - resolved)
        names = sorted(set(args.dll_exports.read_text().split()) - have)
        by_topic["exports"] = [f"short {n}(...);" for n in names if re.match(r"^GTN?_\w+$", n)]
    seen: set[str] = set()
    structs = []
    for td in tds:
        if td.name not in seen:
            seen.add(td.name)
            structs.append(render_struct(td))
    print(f"{len(functions)} functions, {len(structs)} typedefs, {len(consts)} constants")
    prefix = "vendor_gtn_" if args.only_missing else "vendor_"
    for key, title, _ in TOPICS:
        print(f"  {prefix}{key:<14} {len(by_topic.get(key, [])):5d}  {title}")
    if args.only_missing:
        print(f"  {len(resolved)} names declared (...) before now have a prototype")
        write_missing(args.out, by_topic, structs, consts, resolved, args.add)
    elif args.out:
        for key, title, _ in TOPICS:
            if by_topic.get(key):
                (args.out / f"vendor_{key}.py").write_text(
                    render_group(key, title, by_topic[key]), encoding="utf-8"
                )
        cst = "\n".join(f"#define {k} {v}" for k, v in consts.items())
        st = "\n".join(structs)
        (args.out / "vendor_types.py").write_text(
            '"""The vendor headers\' structures, enums and constants (no functions).\n\n'
            'Generated by tools/gts_header_table.py from the vendor headers."""\n\n'
            'NAME = "vendor_types"\nTITLE = "vendor structures and constants"\n'
            'DECLARED_ONLY = True\nPROTOTYPES = ""\n\n'
            f'STRUCTS = r"""\n{st}\n"""\n\nCONSTANTS = r"""\n{cst}\n"""\n',
            encoding="utf-8",
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
