"""``gts.h``, generated from the function table: never edited by hand.

It declares every function of the table (:mod:`gtecat.gt.table`) with the vendor's
prototype (``short`` return, ``long`` stays ``long``), the ``GTN_x(short core, ...)``
twin of every ``GT_x``, the ``GTE_x`` emulator functions, ``GTE_GetLastError``, the
structures ``gt`` exports with the ctypes layout (:mod:`gtecat.native.cdecl` says how
``long`` fields are spelled) and the constants of ``gt``.  C++ sees the vendor's
default arguments; C sees plain prototypes.
"""

from __future__ import annotations

from .. import __version__
from ..gt.table import FUNCTIONS, Proto
from . import cdecl
from .protocol import table_digest

GUARD = "GTECAT_GTS_H"

#: the library's own function (not a controller call): the reason of the last non-zero return
LAST_ERROR_PROTOTYPE = "short GTE_GetLastError(char *buf, short size)"


def _check_defaults(proto: Proto) -> None:
    seen = False
    for p in proto.params:
        if p.default is not None:
            seen = True
        elif seen:
            raise cdecl.CDeclError(
                f"{proto.name}: parameter {p.name} has no default after one that has "
                "(C++ defaults must be trailing)"
            )


def prototypes(*, defaults: bool, abi: str = "") -> list[str]:
    """Every declaration, ``GT_x`` then ``GTN_x`` per table line, table order
    (``abi="gts-multicard"``: ``GT_x`` with ``short cardNum`` first)."""
    out = []
    for proto in FUNCTIONS.values():
        if proto.unknown:
            continue  # exported by the library, parameters unknown: no prototype
        _check_defaults(proto)
        entry = proto.entry
        if entry[:1].isdigit():
            entry = f"manual entry {entry}"
        elif entry == "header":
            entry = "vendor header"
        note = f"  /* {entry} */" if entry else ""
        sig = proto.c_signature(defaults=defaults)
        if abi and proto.name.startswith("GT_"):
            from .multicard import prototype

            sig = prototype(proto, defaults=defaults)
        elif not defaults and not proto.params:
            sig = sig.replace("()", "(void)")  # a C prototype, not an old-style declaration
        out.append(sig + ";" + note)
        if proto.gtn:
            out.append(proto.c_signature(defaults=defaults, core=True) + ";")
    return out


def render(abi: str = "") -> str:
    """The text of ``gts.h`` (``abi="gts-multicard"``: the older multi-card GTS shape)."""
    lines = [
        f"/* gts.h - the GT API of gtecat {__version__} (table {table_digest()}).",
        " *",
        " * Generated from gtecat/gt/table.py by gtecat.native.header: do not edit.",
        " * Link with libgts (python3 -m gtecat lib --cflags --libs).  Every GT_x has a",
        " * GTN_x(short core, ...) twin (core 1 is the EtherCAT core), except GTN_Open(short",
        " * channel, short param) and GTN_Close(void), which as in the vendor's GTN header",
        " * open and close the whole controller.  C++ sees the vendor's",
        " * default arguments, C the plain prototypes.  Functions return the manual's codes;",
        " * GTE_GetLastError says why the last non-zero return happened.",
        " *",
        " * Structure fields the vendor header writes `long` are 32 bits there (Windows);",
        " * they are spelled `int` here so the layout is the same on every platform.",
        " * Function parameters keep `long`; values must fit in 32 bits.",
        " */",
        *(
            [
                "/* The multi-card GTS ABI (gtecat lib --abi gts-multicard): every GT_x takes",
                " * short cardNum first; the emulator is card 0. */",
            ]
            if abi
            else []
        ),
        f"#ifndef {GUARD}",
        f"#define {GUARD}",
        "",
        "#include <stddef.h>",
        "",
        f'#define GTECAT_VERSION "{__version__}"',
        f'#define GTECAT_TABLE_DIGEST "{table_digest()}"',
        "",
        "/* ---- constants ---- */",
    ]
    lines += [c.define() for c in cdecl.constants()]
    lines += ["", "/* ---- enums ---- */"]
    lines += cdecl.enums()
    lines += ["", "/* ---- structures ---- */"]
    known = set()
    for cls in cdecl.structures():
        lines += [cdecl.struct_decl(cls), ""]
        known.add(cls.__name__)
    opaque = sorted({p.ctype for f in FUNCTIONS.values() for p in f.params if p.is_struct} - known)
    if opaque:
        lines.append("/* structures the vendor headers name without a layout gtecat knows */")
        lines += [f"typedef struct {n} {n};" for n in opaque]
        lines.append("")
    lines += [
        "#ifdef __cplusplus",
        'extern "C" {',
        "#endif",
        "",
        "#ifdef __cplusplus",
        "/* ---- functions (C++: with the vendor's default arguments) ---- */",
    ]
    lines += prototypes(defaults=True, abi=abi)
    lines += ["#else", "/* ---- functions ---- */"]
    lines += prototypes(defaults=False, abi=abi)
    lines += [
        "#endif",
        "",
        '/* The reason of this process\'s last non-zero return ("" if none), NUL-terminated',
        " * and cut to size bytes.  Returns 0, or 7 when buf is NULL or size < 1. */",
        LAST_ERROR_PROTOTYPE + ";",
        "",
        "#ifdef __cplusplus",
        "}",
        "#endif",
        "",
        f"#endif /* {GUARD} */",
        "",
    ]
    return "\n".join(lines)


__all__ = ["LAST_ERROR_PROTOTYPE", "prototypes", "render"]
