"""``gts.dll`` for Windows (x64 and x86), cross-compiled with mingw-w64 from the function table.

The same generated sources as ``libgts.so`` (:mod:`gtecat.native.build`: ``gts.h``, the stubs,
the declared-only functions, the hand-written transport ``csrc/gts_runtime.c``), with:

* every GT function ``__stdcall``, as in the vendor's header (``GT_API`` is
  ``extern "C" short __stdcall``); on x64 there is one convention and it changes nothing;
* the export names of the vendor's DLL: on x86 the stdcall names **undecorated** (``GT_Open``,
  not ``_GT_Open@8``), as the vendor's 32-bit ``gts.dll`` exports them, so a C# ``DllImport``,
  a Delphi ``external 'gts.dll'`` or ``GetProcAddress(h, "GT_Open")`` finds them.  A module
  definition file (``gts.def``) lists them, generated from the table (the ``@N`` of each name
  comes from the compiled objects, so the linker checks every one);
* the ~3,800 declared-only functions assembled, as ``libgts.so``'s on x86-64 Linux
  (:func:`gtecat.native.stubs.render_declared_win64`, ``render_declared_win32``; their C
  bodies where the assembler is missing);
* an import library (``gts.lib``) whose symbols are the decorated ones a compiler emits for a
  call through the header, each importing the undecorated name: programs linked against it
  load our DLL, or the vendor's;
* ``long`` is 32 bits there (Windows is LLP64, like the ``libgts-llp64`` build for Mono), so the
  hello announces 4 and the controller sizes ``long *`` accordingly; the transport is TCP over
  winsock (``GTECAT_CONTROLLER=tcp://HOST:PORT`` or ``gtecat.ini`` beside the program).

Nothing is compiled at install time: :func:`ensure_built` builds into the per-version cache on
first use and needs ``x86_64-w64-mingw32-gcc`` / ``i686-w64-mingw32-gcc`` (Debian:
``gcc-mingw-w64-x86-64``, ``gcc-mingw-w64-i686``) only then.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import os
import re
import shlex
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

from .. import __version__
from ..cbuild import NativeBuildError, cache_root, flush, intact, seal
from ..cbuild import version_dir as made_version_dir
from . import build as _build

#: target -> the mingw-w64 tool prefix
TRIPLES = {"x64": "x86_64-w64-mingw32", "x86": "i686-w64-mingw32"}
#: the Debian package of each cross compiler
PACKAGES = {"x64": "gcc-mingw-w64-x86-64", "x86": "gcc-mingw-w64-i686"}
#: what ``gtecat lib --windows`` writes (the sources' own header files besides)
OUTPUTS = ("gts.dll", "gts.lib", "gts.def", "gts.h", "gtecat_vendor.h")
CFLAGS = ("-std=gnu99", "-O2", "-Wall", "-Wextra", "-D__USE_MINGW_ANSI_STDIO=1")
LDFLAGS = ("-shared", "-static-libgcc", "-Wl,--kill-at", "-Wl,--enable-stdcall-fixup")
LIBS = ("-lws2_32",)

_DEFINITION = re.compile(r"^short (G[A-Z]*_\w+)\(", re.M)


@dataclass(frozen=True, slots=True)
class WindowsBuild:
    root: Path
    target: str

    @property
    def dll(self) -> Path:
        return self.root / "gts.dll"

    def files(self) -> list[Path]:
        return [self.root / n for n in OUTPUTS]


def cross_compiler(target: str) -> list[str]:
    """The mingw-w64 gcc of ``target`` (NativeBuildError naming the package when missing)."""
    if target not in TRIPLES:
        raise NativeBuildError(f"--windows {target}: one of {', '.join(TRIPLES)}")
    gcc = f"{TRIPLES[target]}-gcc"
    if not shutil.which(gcc):
        raise NativeBuildError(
            f"{gcc} not found: gts.dll for {target} is cross-compiled with mingw-w64 "
            f"(Debian/Ubuntu: apt-get install {PACKAGES[target]})"
        )
    return [gcc]


def to_stdcall(c_text: str) -> str:
    """Every ``short GT_x(...)`` / ``GTN_x`` / ``GTE_x`` declaration or definition at the start
    of a line becomes ``short __stdcall GT_x(...)``."""
    return _DEFINITION.sub(r"short __stdcall \1(", c_text)


#: target -> the declared-only functions in assembly (:func:`declared_units`)
DECLARED_ASM = {"x64": "gts_declared_win64.S", "x86": "gts_declared_win32.S"}


def sources(target: str | None = None) -> dict[str, str]:
    """The files of the DLL build: libgts's, the GT functions made ``__stdcall``; with a
    ``target``, its declared-only functions in assembly besides."""
    from . import stubs

    files = _build.sources(_build.python_executable())
    del files[_build.DECLARED_ASM]  # Linux's (ELF, System V)
    for name in ("gts.h", "gts_stubs.c", "gts_declared.c"):
        files[name] = to_stdcall(files[name])
    if target == "x64":
        files[DECLARED_ASM[target]] = stubs.render_declared_win64()
    elif target == "x86":
        files[DECLARED_ASM[target]] = stubs.render_declared_win32()
    return files


def declared_units(
    target: str, cc: list[str], files: dict[str, str]
) -> list[tuple[str, tuple[str, ...]]]:
    """The declared-only functions' units and the flags of each: assembled (a few hundredths
    of a second where gcc takes seconds for the ~3,800 C bodies), the C unit compiled for its
    table alone; the C bodies where the target has no assembly or its assembler is missing."""
    from .stubs import DECLARED_ASM_MACRO

    flags = (*CFLAGS, *_build.STUB_CFLAGS)
    asm = DECLARED_ASM.get(target)
    if asm in files and shutil.which(cc[0][: -len("gcc")] + "as"):
        return [("gts_declared.c", (*flags, f"-D{DECLARED_ASM_MACRO}")), (asm, ())]
    return [("gts_declared.c", flags)]


def export_names(files: dict[str, str]) -> list[str]:
    """Every function the DLL exports, in table order: the GT / GTN / GTE functions the stubs
    and the declared-only unit define, and ``GTE_GetLastError``."""
    names: list[str] = []
    seen = set()
    for unit in ("gts_stubs.c", "gts_declared.c"):
        for line in files[unit].splitlines():
            if line.endswith(";"):
                continue  # a declaration (the unknown prototypes of gts_declared.c)
            m = re.match(r"short __stdcall (\w+)\(", line)
            if m and m.group(1) not in seen:
                seen.add(m.group(1))
                names.append(m.group(1))
    names.append("GTE_GetLastError")
    return names


def ensure_built(target: str, *, force: bool = False) -> WindowsBuild:
    """``gts.dll`` for ``target`` ("x64" | "x86"), compiled into the cache if needed."""
    cc = cross_compiler(target)
    files = sources(target)
    h = hashlib.sha256()
    for name in sorted(files):
        h.update(name.encode() + b"\0" + files[name].encode() + b"\0")
    h.update(" ".join([*cc, *CFLAGS, *LDFLAGS, *LIBS]).encode())
    h.update(Path(__file__).read_bytes())  # this recipe: a changed build builds again
    build = WindowsBuild(cache_root() / __version__ / f"win-{target}-{h.hexdigest()[:12]}", target)
    if all(f.is_file() for f in build.files()) and intact(build.dll) and not force:
        return build
    vdir = made_version_dir()
    with open(vdir / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if all(f.is_file() for f in build.files()) and intact(build.dll) and not force:
            return build
        _compile(build, files, cc)
    return build


def _run(cmd: list[str], what: str, cwd: Path | None = None) -> str:
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd)
    if r.returncode != 0:
        raise NativeBuildError(f"building {what} failed ({shlex.join(cmd)}):\n{r.stderr.strip()}")
    if r.stderr.strip():
        raise NativeBuildError(f"building {what} warned (it must not):\n{r.stderr.strip()}")
    return r.stdout


def _compile(build: WindowsBuild, files: dict[str, str], cc: list[str]) -> None:
    what = f"gts.dll ({build.target})"
    tmp = Path(tempfile.mkdtemp(prefix=".win-", dir=build.root.parent))
    try:
        for name, text in files.items():
            (tmp / name).write_text(text, encoding="utf-8")
        # the transport optimised; the stubs (they pack arguments for a network round trip)
        # not, as libgts's: -O0 takes a third of the time, no asynchronous unwind tables a
        # quarter less again; the ~3,800 declared-only functions assembled
        units = [
            ("gts_runtime.c", CFLAGS),
            ("gts_stubs.c", (*CFLAGS, *_build.STUB_CFLAGS)),
            *declared_units(build.target, cc, files),
        ]
        objs = _build.compile_units(units, [*cc, f"-I{tmp}"], tmp, what)
        names = export_names(files)
        decorated = _decorated(build.target, cc, objs) if build.target == "x86" else {}
        missing = [n for n in names if build.target == "x86" and n not in decorated]
        if missing:
            raise NativeBuildError(
                f"building {what}: no stdcall symbol for {', '.join(missing[:5])}"
            )
        lines = ["LIBRARY gts.dll", "EXPORTS", *(decorated.get(n, n) for n in names), ""]
        (tmp / "gts.def").write_text("\n".join(lines), encoding="ascii")
        cmd = [*cc, *LDFLAGS, *objs, str(tmp / "gts.def"), *LIBS, "-o", str(tmp / "gts.dll")]
        _run(cmd, what)
        # the import library from the same .def: its symbols keep the decoration a compiler
        # emits for a __stdcall call (_GT_Open@8), each importing the undecorated name (-k)
        dlltool = cc[0][: -len("gcc")] + "dlltool"
        cmd = [
            dlltool,
            "-k",
            "-d",
            str(tmp / "gts.def"),
            "-D",
            "gts.dll",
            "-l",
            str(tmp / "gts.lib"),
        ]
        _import_library(cmd, what + " import library", tmp)
        out = tmp / "out"
        out.mkdir()
        for name in OUTPUTS:
            shutil.copy2(tmp / name, out / name)
        flush(out / "gts.dll")
        seal(out / "gts.dll")  # (its seal goes with it: the folder is renamed into place whole)
        if build.root.exists():
            shutil.rmtree(build.root)
        out.rename(build.root)
    finally:
        with contextlib.suppress(OSError):
            shutil.rmtree(tmp)


#: a memory file system for dlltool's temporary objects, where there is one
_SCRATCH = Path("/dev/shm")


def _import_library(cmd: list[str], what: str, folder: Path) -> None:
    """Run dlltool: it writes a temporary object per exported name (~2,900) into its working
    folder, so it works in a folder of the memory file system where there is one (on a disk,
    creating and deleting them takes two to four times the system time), else in the build's
    ``folder``."""
    if _SCRATCH.is_dir() and os.access(_SCRATCH, os.W_OK | os.X_OK):
        try:
            with tempfile.TemporaryDirectory(prefix="gtecat-dlltool-", dir=_SCRATCH) as scratch:
                _run(cmd, what, cwd=Path(scratch))
            return
        except (OSError, NativeBuildError):
            pass  # full or unusable: again in the build's folder, which says why if it fails
    _run(cmd, what, cwd=folder)


def _decorated(target: str, cc: list[str], objs: list[str]) -> dict[str, str]:
    """name -> ``name@N`` of every stdcall function the objects define (x86)."""
    nm = cc[0][: -len("gcc")] + "nm"
    out = _run([nm, "-g", "--defined-only", *objs], "gts.dll (reading its symbols)")
    found = {}
    for line in out.splitlines():
        m = re.match(r"^[0-9a-fA-F]+ T _(\w+)@(\d+)$", line.strip())
        if m:
            found[m.group(1)] = f"{m.group(1)}@{m.group(2)}"
    return found


def write(target: str, directory: str | Path, *, force: bool = False) -> list[Path]:
    """Build (or take from the cache) and copy ``gts.dll``, ``gts.lib``, ``gts.def``, ``gts.h``
    and ``gtecat_vendor.h`` into ``directory``; the paths written."""
    build = ensure_built(target, force=force)
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    written = []
    for f in build.files():
        shutil.copyfile(f, d / f.name)
        written.append(d / f.name)
    return written


def pe_exports(data: bytes) -> tuple[str, list[str]]:
    """(machine: "x86" | "x64" | hex, exported names) of a PE file's bytes: a small reader of
    the export directory (PE/COFF: DOS header -> PE signature -> optional header -> data
    directory 0), so a test or a user can check a DLL without Windows tools."""
    import struct

    if data[:2] != b"MZ":
        raise ValueError("not a PE file (no MZ header)")
    (pe,) = struct.unpack_from("<I", data, 0x3C)
    if data[pe : pe + 4] != b"PE\0\0":
        raise ValueError("not a PE file (no PE signature)")
    machine, nsect, _, _, _, opt_size, _ = struct.unpack_from("<HHIIIHH", data, pe + 4)
    opt = pe + 24
    magic = struct.unpack_from("<H", data, opt)[0]
    ddir = opt + (96 if magic == 0x10B else 112)
    export_rva, _ = struct.unpack_from("<II", data, ddir)
    sections = []
    sect = opt + opt_size
    for i in range(nsect):
        vsize, va, rsize, rptr = struct.unpack_from("<IIII", data, sect + 40 * i + 8)
        sections.append((va, max(vsize, rsize), rptr))

    def off(rva: int) -> int:
        for va, size, rptr in sections:
            if va <= rva < va + size:
                return rptr + rva - va
        raise ValueError(f"RVA {rva:#x} is in no section")

    name = {0x14C: "x86", 0x8664: "x64"}.get(machine, hex(machine))
    if not export_rva:
        return name, []
    e = off(export_rva)
    # IMAGE_EXPORT_DIRECTORY: NumberOfNames at +24, AddressOfNames at +32
    (n_names,) = struct.unpack_from("<I", data, e + 24)
    table = off(struct.unpack_from("<I", data, e + 32)[0])
    out = []
    for i in range(n_names):
        (rva,) = struct.unpack_from("<I", data, table + 4 * i)
        start = off(rva)
        out.append(data[start : data.index(b"\0", start)].decode("ascii", "replace"))
    return name, out


__all__ = [
    "OUTPUTS",
    "PACKAGES",
    "TRIPLES",
    "WindowsBuild",
    "cross_compiler",
    "declared_units",
    "ensure_built",
    "export_names",
    "pe_exports",
    "sources",
    "to_stdcall",
    "write",
]
