"""The Windows DLLs' declared-only functions in assembly (gtecat.native.stubs).

The ~3,800 functions are assembled for x64 and x86 instead of compiled; on x86 each is
``__stdcall`` and its symbol carries the bytes of arguments it pops (``_GT_x@N``), which
the stubs compute from the table.  The default run proves every ``N``: one C function per
distinct list of parameter types of the table (pointers are one type), compiled by
mingw-w64's gcc, must be decorated as the stubs decorate each function of that list.
GTECAT_LONG=1 compares the symbols of the whole assembled unit with those of the C bodies.
The import library's ~2,900 temporary objects go to a memory file system where there is one.
(tests/gtecat/native/test_windows.py runs the DLLs' functions under Wine.)
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from gtecat.native import cdecl, stubs, windows


def _tool(target: str, tool: str) -> str:
    exe = f"{windows.TRIPLES[target]}-{tool}"
    if shutil.which(exe) is None:
        pytest.skip(
            f"{exe} not found: install the Debian package of .ci/deps/mingw.sh "
            f"({windows.PACKAGES[target]})"
        )
    return exe


def _symbols(target: str, obj: Path) -> set[str]:
    r = subprocess.run(
        [_tool(target, "nm"), "-g", "--defined-only", str(obj)],
        capture_output=True,
        text=True,
        check=True,
    )
    return {ln.split()[-1] for ln in r.stdout.splitlines() if " T " in ln}


def _compile(target: str, folder: Path, src: str, *flags: str) -> Path:
    obj = folder / (src.rsplit(".", 1)[0] + ".o")
    cmd = [_tool(target, "gcc"), "-std=gnu99", "-O0", f"-I{folder}", *flags, "-c"]
    r = subprocess.run([*cmd, str(folder / src), "-o", str(obj)], capture_output=True, text=True)
    assert r.returncode == 0 and not r.stderr.strip(), r.stderr
    return obj


@pytest.fixture(scope="module")
def x86_sources(tmp_path_factory) -> tuple[Path, dict[str, str]]:
    """The x86 DLL's sources, written once."""
    _tool("x86", "gcc")
    folder = tmp_path_factory.mktemp("win32")
    files = windows.sources("x86")
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8")
    return folder, files


def test_every_stdcall_byte_count_is_the_compilers(x86_sources):
    folder, files = x86_sources
    shapes: dict[tuple[str, ...], list[int]] = {}
    for proto, gtn, _, _ in stubs._declared_bodies():
        params = stubs._twin_params(proto, gtn)
        shape = tuple("void *" if pointer else ctype for ctype, pointer in params)
        shapes.setdefault(shape, []).append(stubs.stdcall_bytes(proto, gtn))
    assert all(len(set(ns)) == 1 for ns in shapes.values())  # N is the shape's
    assert len(shapes) > 100  # (496 lists of types in the table of this writing)
    lines = ['#include "gts.h"']
    for cls in cdecl.structures():  # every structure's size, should one go by value
        size = stubs._i686_layout(cls)[0]
        lines.append(f'_Static_assert(sizeof({cls.__name__}) == {size}, "{cls.__name__}");')
    for k, shape in enumerate(shapes):
        params = ", ".join(f"{t} a{j}" for j, t in enumerate(shape)) or "void"
        lines.append(f"short __stdcall S{k}({params}) {{ return 0; }}")
    (folder / "shapes.c").write_text("\n".join(lines) + "\n", encoding="utf-8")
    compiled = {}
    for sym in _symbols("x86", _compile("x86", folder, "shapes.c")):
        m = re.fullmatch(r"_S(\d+)@(\d+)", sym)
        if m:
            compiled[int(m.group(1))] = int(m.group(2))
    ours = {k: ns[0] for k, ns in enumerate(shapes.values())}
    wrong = {list(shapes)[k]: (n, compiled.get(k)) for k, n in ours.items() if compiled.get(k) != n}
    assert not wrong, f"(ours, gcc's) per parameter list: {wrong}"
    # each assembled symbol is the stub's name decorated with its shape's N
    asm = files[windows.DECLARED_ASM["x86"]]
    labels = re.findall(r"^(_\w+(?:@\d+)?):$", asm, re.M)
    assert len(labels) == len(stubs._declared_bodies())
    assert "_GTN_ArcXYCOverride2@64" in labels and "_ConvertPhysical" in labels  # (cdecl)


@pytest.mark.long("the whole assembled x86 unit against the C bodies")
def test_the_assembled_x86_unit_defines_what_the_c_bodies_define(x86_sources):
    folder, _ = x86_sources
    c_bodies = _symbols("x86", _compile("x86", folder, "gts_declared.c"))
    asm = _symbols("x86", _compile("x86", folder, windows.DECLARED_ASM["x86"]))
    assert len(asm) > 3000 and asm == c_bodies


def test_the_x64_stubs_pass_the_core_before_the_index(tmp_path):
    text = stubs.render_declared_win64()
    body = text.split("GTN_ArcXYCOverride2:\n", 1)[1].split("\n\t.globl", 1)[0].splitlines()
    assert body[0] == "\tmovswl %cx, %r8d"  # core, read before %ecx is the index
    assert body[1].startswith("\tmovl $") and body[1].endswith(", %ecx")
    assert body[2:] == ["\tmovl $1, %edx", "\tjmp gte_declared"]
    assert not re.search(r"^\t\.(type|size) |\.note|@function|@PLT", text, re.M)  # PE/COFF
    src = tmp_path / "gts_declared_win64.S"
    src.write_text(text, encoding="utf-8")
    obj = _compile("x64", tmp_path, src.name)
    names = _symbols("x64", obj)
    assert {"GT_SetHSIOOpt", "GTN_SetHSIOOpt", "ConvertPhysical"} <= names
    assert len(names) == len(stubs._declared_bodies())


def test_without_an_assembler_the_dll_takes_the_c_bodies(monkeypatch):
    files = {"gts_declared.c": "", windows.DECLARED_ASM["x86"]: ""}
    cc = ["i686-w64-mingw32-gcc"]
    monkeypatch.setattr(windows.shutil, "which", lambda exe: "/usr/bin/" + exe)
    assembled = windows.declared_units("x86", cc, files)
    assert [name for name, _ in assembled] == ["gts_declared.c", "gts_declared_win32.S"]
    assert f"-D{stubs.DECLARED_ASM_MACRO}" in assembled[0][1]
    assert [name for name, _ in windows.declared_units("arm64", cc, files)] == ["gts_declared.c"]
    monkeypatch.setattr(windows.shutil, "which", lambda exe: None)
    fallback = windows.declared_units("x86", cc, files)
    assert fallback == [("gts_declared.c", (*windows.CFLAGS, *windows._build.STUB_CFLAGS))]


def test_the_import_library_is_made_in_scratch_or_the_build_folder(tmp_path, monkeypatch):
    dlltool = _tool("x86", "dlltool")
    (tmp_path / "t.def").write_text("LIBRARY gts.dll\nEXPORTS\nGT_Open@8\n", encoding="ascii")
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    for where in (scratch, tmp_path / "missing"):  # a memory file system, or none
        monkeypatch.setattr(windows, "_SCRATCH", where)
        lib = tmp_path / f"{where.name}.lib"
        cmd = [dlltool, "-k", "-d", str(tmp_path / "t.def"), "-D", "gts.dll", "-l", str(lib)]
        windows._import_library(cmd, "gts.lib", tmp_path)
        assert "_GT_Open@8" in _symbols("x86", lib)
    assert not list(scratch.iterdir())  # its temporary folder gone
    with pytest.raises(windows.NativeBuildError, match=r"gts\.lib failed"):
        windows._import_library([dlltool, "-d", str(tmp_path / "none.def")], "gts.lib", tmp_path)
