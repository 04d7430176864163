"""gts.h against the function table: same functions, same prototypes, same layouts.

The header is read back with a parser of its own (not the generator's code), so a
generator that drifts from the table fails here; the structures are compared to the
ctypes ones through ``sizeof``/``offsetof`` printed by a compiled C program.
"""

from __future__ import annotations

import ctypes
import dataclasses
import re
import subprocess

import pytest

from gtecat import gt
from gtecat.gt.table import FUNCTIONS, GROUPS, NO_CORE_TWINS, SAME_PARAM_TWINS, collect
from gtecat.native import cdecl, header

from .conftest import needs_cc, needs_cxx

_PROTO = re.compile(r"^short\s+(\w+)\((.*)\);")


def _blocks(text: str) -> tuple[list[str], list[str]]:
    """The C++ declarations and the C declarations of the header."""
    cxx = text.split("/* ---- functions (C++", 1)[1].split("#else", 1)[0]
    c = text.split("/* ---- functions ---- */", 1)[1].split("#endif", 1)[0]
    return cxx.splitlines(), c.splitlines()


def _read(lines: list[str]) -> dict[str, list[tuple[str, str, str | None]]]:
    """name -> [(type, name, default)] from declaration lines."""
    out = {}
    for line in lines:
        m = _PROTO.match(line.strip())
        if not m:
            continue
        params = []
        for part in filter(None, (x.strip() for x in m[2].split(","))):
            if part == "void":
                continue
            decl, _, default = part.partition("=")
            pm = re.match(r"^(.*?)(\**)\s*(\w+)$", decl.strip())
            assert pm, part
            ctype = pm[1].strip() + (" " + pm[2] if pm[2] else "")
            params.append((re.sub(r"\s+", " ", ctype), pm[3], default.strip() or None))
        out[m[1]] = params
    return out


def _expected(functions, *, defaults: bool) -> dict[str, list[tuple[str, str, str | None]]]:
    out = {}
    for proto in functions.values():
        if proto.unknown:  # the vendor DLL's name without public parameters: not in gts.h
            continue
        ps = [
            (
                ("const " if p.text and p.direction == "in" else "")  # input text: const char *
                + p.ctype
                + (" " + "*" * p.stars if p.pointer else ""),
                p.name,
                p.default if defaults else None,
            )
            for p in proto.params
        ]
        out[proto.name] = ps
        if proto.name in NO_CORE_TWINS:  # the vendor's GTN_Open(channel, param), GTN_Close()
            out["GTN_" + proto.name[3:]] = [
                ("short", n, d if defaults else None) for n, d in NO_CORE_TWINS[proto.name]
            ]
        elif proto.name in SAME_PARAM_TWINS:  # GTN_Compile(pFileName, ...): no core
            out["GTN_" + proto.name[3:]] = ps
        elif proto.gtn:
            out["GTN_" + proto.name[3:]] = [("short", "core", None), *ps]
    return out


def disagreements(text: str, functions) -> list[str]:
    """What differs between a header text and a table (empty: they agree)."""
    cxx, c = _blocks(text)
    problems = []
    for label, lines, with_defaults in (("C++", cxx, True), ("C", c, False)):
        got = _read(lines)
        want = _expected(functions, defaults=with_defaults)
        for name in sorted(set(want) - set(got)):
            problems.append(f"{label}: {name} missing from gts.h")
        for name in sorted(set(got) - set(want)):
            problems.append(f"{label}: {name} in gts.h but not in the table")
        for name in sorted(set(got) & set(want)):
            if got[name] != want[name]:
                problems.append(f"{label}: {name}: header {got[name]} != table {want[name]}")
    if "short GTE_GetLastError(char *buf, short size);" not in text:
        problems.append("GTE_GetLastError missing")
    return problems


def test_header_declares_the_table_exactly():
    assert disagreements(header.render(), FUNCTIONS) == []


@pytest.mark.long
def test_a_drifted_table_is_noticed():
    text = header.render()
    groups = []
    for g in GROUPS:
        if "GT_GetSts(" in g.prototypes:
            lines = g.prototypes.replace(
                "short count=1, unsigned long *pClock=NULL);  // 71", "short count=2);"
            )
            g = dataclasses.replace(g, prototypes=lines + "\nshort GT_NotThere(short axis);\n")
        groups.append(g)
    changed = collect(groups)
    problems = disagreements(text, changed)
    assert any("GT_GetSts" in p for p in problems)
    assert any("GT_NotThere missing" in p for p in problems)
    assert any("GTN_NotThere missing" in p for p in problems)


def test_vendor_prototypes_and_defaults():
    text = header.render()
    cxx, c = _blocks(text)
    assert (
        "short GT_GetSts(short axis, long *pSts, short count=1, unsigned long *pClock=NULL);"
        in "\n".join(cxx)
    )
    assert "short GT_ZeroPos(short axis, short count=1);" in "\n".join(cxx)
    assert "short GT_Open(short channel=0, short param=1);" in "\n".join(cxx)
    c_text = "\n".join(c)
    assert "short GT_GetSts(short axis, long *pSts, short count, unsigned long *pClock);" in c_text
    assert (
        "short GTN_GetSts(short core, short axis, long *pSts, short count, unsigned long *pClock);"
        in c_text
    )
    assert "short GT_Close(void);" in c_text
    assert not any("GTN_Wait(" in line for line in c)  # GTE_ helpers have no twin


def test_constants_match_gt():
    text = header.render()
    defines = dict(re.findall(r"^#define (\w+) (.+)$", text, re.M))
    for c in cdecl.constants():
        assert c.name in defines, c.name
        got = defines[c.name].strip("()")
        if isinstance(c.value, int):
            assert int(got.rstrip("LU")) == c.value
    assert defines["MC_GPO"] == "12"
    assert defines["MC_NONE"] == "(-1)"


@needs_cc
def test_compiles_warning_free_as_c99(tmp_path, gts_h):
    src = tmp_path / "t.c"
    src.write_text('#include "gts.h"\nint main(void) { return GT_Open(0, 1) ? 0 : 0; }\n')
    for std in ("-std=c99", "-std=c11"):
        r = subprocess.run(
            [
                "gcc",
                std,
                "-Wall",
                "-Wextra",
                "-Wstrict-prototypes",
                "-pedantic",
                "-Werror",
                f"-I{gts_h.parent}",
                "-fsyntax-only",
                str(src),
            ],
            capture_output=True,
            text=True,
        )
        assert r.returncode == 0, r.stderr


@needs_cxx
def test_compiles_warning_free_as_cxx11_with_defaults(tmp_path, gts_h):
    src = tmp_path / "t.cpp"
    src.write_text(
        '#include "gts.h"\n'
        "int main() {\n"
        "    long sts; double pos; TTrapPrm trap; unsigned long clk;\n"
        "    GT_Open(); GT_GetSts(1, &sts); GT_GetSts(1, &sts, 1, &clk); GT_ZeroPos(1);\n"
        "    GT_GetPrfPos(1, &pos); GTN_GetSts(1, 1, &sts); GT_GetTrapPrm(1, &trap);\n"
        "    GT_ClrSts(1, 4); GT_LmtsOn(1); GT_PtData(1, 1.0, 10);\n"
        "    char buf[64]; return GTE_GetLastError(buf, sizeof buf);\n"
        "}\n"
    )
    r = subprocess.run(
        [
            "g++",
            "-std=c++11",
            "-Wall",
            "-Wextra",
            "-pedantic",
            "-Werror",
            f"-I{gts_h.parent}",
            "-fsyntax-only",
            str(src),
        ],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0, r.stderr


@needs_cc
@pytest.mark.long
def test_structure_layout_equals_ctypes(tmp_path, gts_h):
    structs = cdecl.structures()
    assert {"TTrapPrm", "TJogPrm", "TThreadSts", "TVarInfo", "TCompileInfo", "TSlaveInfo"} <= {
        s.__name__ for s in structs
    }
    body = []
    want = []
    for cls in structs:
        n = cls.__name__
        body.append(f'printf("{n} %zu\\n", sizeof({n}));')
        want.append(f"{n} {ctypes.sizeof(cls)}")
        for f in cls._fields_:
            body.append(f'printf("{n}.{f[0]} %zu\\n", offsetof({n}, {f[0]}));')
            want.append(f"{n}.{f[0]} {getattr(cls, f[0]).offset}")
    src = tmp_path / "layout.c"
    src.write_text(
        '#include <stdio.h>\n#include <stddef.h>\n#include "gts.h"\n'
        "int main(void) {\n    " + "\n    ".join(body) + "\n    return 0;\n}\n"
    )
    exe = tmp_path / "layout"
    subprocess.run(
        ["gcc", "-std=c99", "-Wall", f"-I{gts_h.parent}", str(src), "-o", str(exe)], check=True
    )
    got = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout.split("\n")
    assert got[:-1] == want


def test_structures_are_the_ones_gt_exports():
    names = [s.__name__ for s in cdecl.structures()]
    assert names.index("TTrapPrm") < names.index("TJogPrm")
    for n in names:
        assert getattr(gt, n) is cdecl.structure(n)


def test_unspellable_structures_are_refused():
    class Bits(ctypes.Structure):
        _fields_ = (("a", ctypes.c_uint16, 3),)

    with pytest.raises(cdecl.CDeclError, match="bit fields"):
        cdecl.struct_decl(Bits)
