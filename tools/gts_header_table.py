"""Turn vendor GT headers into candidate function-table groups (a maintainer tool).

    python tools/gts_header_table.py gts.h [more headers...]            # print a summary
    python tools/gts_header_table.py --out gtecat/gt/groups gts.h ...  # write vendor_*.py

Reads the ``GT_API`` prototypes, ``typedef struct/union/enum`` blocks and numeric
``#define`` constants of the headers the maintainer names (GBK or UTF-8, as they ship) and
writes them in the table's syntax as *declared-only* group modules
(``DECLARED_ONLY = True``): ``vendor_<topic>.py`` per topic, ``vendor_types.py`` with the
structures and constants.  Where headers disagree the first header named wins, so name the
newest first.  A ``GTN_x`` equal to ``short core`` + ``GT_x`` becomes one ``GT_x`` line
(the table gives the twin); otherwise both lines are written.  A header whose functions
take ``short cardNum`` first (the older multi-card GTS ABI) gives its functions without
that parameter, after every other header (``gtecat lib --abi gts-multicard`` puts it
back).  Comments of the headers are not carried over.
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


def params(text: str, where: str) -> list[str]:
    """The parameters in table syntax (``type *name=default``)."""
    text = " ".join(text.split())
    for cb in (*CALLBACKS, "HANDLE", "LPVOID"):  # a pointer whatever it points to
        text = re.sub(rf"\b{cb}\b\s*", "void *", text)
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
    return [re.sub(r"\s*\w+(\[\d*\])?(=.*)?$", "", p) for p in ps]


def topic(name: str) -> str:
    bare = re.sub(r"^GTN?_", "", name)
    for key, _, pattern in TOPICS:
        if re.search(pattern, bare):
            return key
    return "basic"


def extract(paths: list[Path]) -> tuple[dict[str, list[str]], list, dict]:
    functions: dict[str, list[str]] = {}
    tds: list = []
    consts: dict[str, int | float] = {}
    multi: list[tuple[str, list[str]]] = []
    for path in paths:
        text = typedefs.strip_comments(read(path))
        CALLBACKS.update(_CALLBACK.findall(text))
        found = [(m[1], params(m[2], f"{path}:{m[1]}")) for m in _API.finditer(text)]
        firsts = [ps[0] for n, ps in found if n.startswith("GT_") and ps]
        if firsts and sum("cardNum" in p for p in firsts) > len(firsts) / 2:
            # the multi-card ABI: the same functions with short cardNum first
            found = [(n, ps[1:] if ps and "cardNum" in ps[0] else ps) for n, ps in found]
            multi.extend(found)
        else:
            for name, ps in found:
                functions.setdefault(name, ps)
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
            try:
                tds.extend(typedefs.parse(block, known=consts))
            except typedefs.TypedefError as e:
                print(f"{path}: skipped: {e}", file=sys.stderr)
    for name, ps in multi:  # after every single-card header: those win
        functions.setdefault(name, ps)
    return functions, tds, consts


def lines(functions: dict[str, list[str]]) -> dict[str, list[str]]:
    by_topic: dict[str, list[str]] = defaultdict(list)
    for name in sorted(functions, key=lambda n: (re.sub(r"^GTN?_", "", n), n)):
        ps = functions[name]
        if name.startswith("GTN_"):
            gt = functions.get("GT_" + name[4:])
            if gt is not None and _types(ps) == ["short", *_types(gt)]:
                continue  # the GT_x line gives it
        by_topic[topic(name)].append(f"short {name}({', '.join(ps)});")
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
    args = ap.parse_args(argv)
    functions, tds, consts = extract(args.headers)
    by_topic = lines(functions)
    if args.dll_exports:
        have = set(functions)
        have |= {  # the twins the table gives (a GT_x that takes the core itself has none)
            "GTN_" + n[3:]
            for n, ps in functions.items()
            if n.startswith("GT_") and not (ps and re.search(r"\bcore$", ps[0]))
        }
        names = sorted(set(args.dll_exports.read_text().split()) - have)
        by_topic["exports"] = [f"short {n}(...);" for n in names if re.match(r"^GTN?_\w+$", n)]
    seen: set[str] = set()
    structs = []
    for td in tds:
        if td.name not in seen:
            seen.add(td.name)
            structs.append(render_struct(td))
    print(f"{len(functions)} functions, {len(structs)} typedefs, {len(consts)} constants")
    for key, title, _ in TOPICS:
        print(f"  vendor_{key:<14} {len(by_topic.get(key, [])):5d}  {title}")
    if args.out:
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
