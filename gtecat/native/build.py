"""Build ``libgts.so`` and ``gts.h`` on first use, into a per-version cache.

``pip install`` needs no C compiler: nothing is compiled until a program asks for
the library (``python3 -m gtecat lib ...``, :func:`gtecat.native.library_path`).
The build writes the generated sources (``gts.h``, ``gts_wire.h``, ``gts_stubs.c``,
``gts_declared.c``, and ``gts_declared_x86_64.S`` for an x86-64 Linux target)
and the hand-written transport (``csrc/``) into
``$GTECAT_CACHE_DIR`` (else ``$XDG_CACHE_HOME/gtecat``, else ``~/.cache/gtecat``)
``/<version>/<digest>/`` and compiles them there with ``$CC`` (else ``cc``, ``gcc``,
``clang``).  ``<digest>`` names the sources, the compiler and the Python interpreter
compiled in, so a changed table or another interpreter gets a build of its own and
concurrent builders never overwrite each other's files (a lock file serialises them).
"""

from __future__ import annotations

import contextlib
import fcntl
import functools
import hashlib
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from .. import __version__
from ..cbuild import NativeBuildError, cache_root, compiler, damaged, flush, intact, seal
from ..cbuild import version_dir as made_version_dir

RUNTIME_SOURCES = ("gts_runtime.c", "gts_runtime.h", "gtecat_vendor.h")
#: files that go beside gts.h (the rest are the library's sources)
INCLUDE_FILES = ("gts.h", "gtecat_vendor.h")
#: the file ``--cflags`` force-includes so a vendor header compiles unchanged
VENDOR_COMPAT = "gtecat_vendor.h"
CFLAGS = ("-std=c99", "-O2", "-fPIC", "-Wall", "-Wextra", "-pthread")
#: the thousands of one-line stubs (declared-only functions, the multi-card layer)
STUB_CFLAGS = ("-O0", "-fno-asynchronous-unwind-tables")
#: the declared-only functions in x86-64 assembly (:func:`declared_units`)
DECLARED_ASM = "gts_declared_x86_64.S"


@functools.cache
def _targets_x86_64_elf(cc: tuple[str, ...]) -> bool:
    try:
        r = subprocess.run([*cc, "-dumpmachine"], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.SubprocessError):
        return False
    machine = r.stdout.strip()
    return r.returncode == 0 and machine.startswith("x86_64-") and "linux" in machine


def declared_units(cc: list[str], extra: tuple[str, ...] = ()) -> list[tuple[str, tuple[str, ...]]]:
    """The declared-only functions' units and the flags of each: on an x86-64 Linux
    target the functions assembled (:func:`gtecat.native.stubs.render_declared_x86_64`) and
    the C unit compiled for its table alone, a hundredth of the time the ~3,800 C bodies
    take; elsewhere (``-m32``, another machine) the C bodies."""
    from .stubs import DECLARED_ASM_MACRO

    if "-m32" not in extra and _targets_x86_64_elf(tuple(cc)):
        return [
            ("gts_declared.c", (*CFLAGS, *STUB_CFLAGS, f"-D{DECLARED_ASM_MACRO}")),
            (DECLARED_ASM, ()),
        ]
    return [("gts_declared.c", (*CFLAGS, *STUB_CFLAGS))]


#: the library of each ABI: the vendor's (GTN era, one card) and the older multi-card GTS one
LIBRARIES = {"": "libgts.so", "gts-multicard": "libgts_mc.so"}


@dataclass(frozen=True, slots=True)
class Build:
    root: Path
    abi: str = ""
    #: the libgts build a multi-card libgts_mc is a layer over (None for libgts itself)
    base: Build | None = None

    @property
    def include_dir(self) -> Path:
        return self.root / "include"

    @property
    def lib_dir(self) -> Path:
        return self.root / "lib"

    @property
    def library(self) -> Path:
        return self.lib_dir / LIBRARIES[self.abi]

    @property
    def header(self) -> Path:
        return self.include_dir / "gts.h"

    def cflags(self) -> list[str]:
        """``-I`` for gts.h, and the forced include that lets the vendor's own header
        compile unchanged (``__stdcall``, NULL, Windows type names: gtecat_vendor.h)."""
        return [f"-I{self.include_dir}", "-include", str(self.include_dir / VENDOR_COMPAT)]

    def libs(self) -> list[str]:
        name = LIBRARIES[self.abi][3:-3]
        own = [f"-L{self.lib_dir}", f"-Wl,-rpath,{self.lib_dir}", f"-l{name}"]
        return own + (self.base.libs() if self.base is not None else [])


def python_executable() -> str:
    """The interpreter a private controller runs on (GTECAT_PYTHON overrides at run time)."""
    return os.environ.get("GTECAT_PYTHON") or sys.executable or "python3"


def sources(python: str, abi: str = "") -> dict[str, str]:
    """Every file of the build, by name."""
    from . import header, stubs

    out = {
        "gts.h": header.render(),
        "gts_wire.h": stubs.render_wire_h(),
        "gts_stubs.c": stubs.render_stubs(python),
        "gts_declared.c": stubs.render_declared(),
        DECLARED_ASM: stubs.render_declared_x86_64(),
    }
    pkg = resources.files("gtecat.native") / "csrc"
    for name in RUNTIME_SOURCES:
        out[name] = (pkg / name).read_text(encoding="utf-8")
    return out


def multicard_sources() -> dict[str, str]:
    """The files of libgts_mc (a layer over libgts: :mod:`gtecat.native.multicard`)."""
    from . import header, multicard

    pkg = resources.files("gtecat.native") / "csrc"
    return {
        "gts.h": header.render(multicard.ABI),
        "gts_sc.h": header.render(),
        "gts_multicard.c": multicard.render_c(),
        VENDOR_COMPAT: (pkg / VENDOR_COMPAT).read_text(encoding="utf-8"),
    }


def _digest(files: dict[str, str], cc: list[str]) -> str:
    h = hashlib.sha256()
    for name in sorted(files):
        h.update(name.encode() + b"\0" + files[name].encode() + b"\0")
    h.update(" ".join([*cc, *CFLAGS]).encode())
    return h.hexdigest()[:12]


def ensure_built(*, force: bool = False, abi: str = "") -> Build:
    """The build for this gtecat, compiled now if it is not in the cache yet
    (``abi="gts-multicard"``: libgts_mc.so, :mod:`gtecat.native.multicard`)."""
    if abi not in LIBRARIES:
        raise NativeBuildError(f"--abi {abi}: one of {', '.join(a for a in LIBRARIES if a)}")
    cc = compiler()
    base = None
    if abi:
        base = ensure_built(force=force)
    version_dir = cache_root() / __version__
    python = python_executable()
    known = version_dir / "inputs" / _inputs(python, abi, cc)
    if not force:
        with contextlib.suppress(OSError):
            build = Build(version_dir / known.read_text(encoding="utf-8").strip(), abi, base)
            if intact(build.library) and build.header.is_file():
                return build
    if abi:
        files = multicard_sources()
        files["base"] = str(base.root)  # the digest names the libgts it is a layer over
    else:
        files = sources(python)
    build = Build(version_dir / _digest(files, cc), abi, base)
    if not (intact(build.library) and build.header.is_file()) or force:
        version_dir = made_version_dir()
        with open(version_dir / ".lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            if not (intact(build.library) and build.header.is_file()) or force:
                if not force:
                    damaged(build.library)
                _compile(build, files, cc)
    _remember(known, build.root.name)
    return build


def _inputs(python: str, abi: str, cc: list[str]) -> str:
    """A name for what the generated sources are made of: every file of this gtecat, the
    interpreter, the ABI and the compiler.  A build found by it is used without rendering
    the sources again, which needs the whole GT layer imported (most of a second); a
    changed file of the package (an editable install) gives another name."""
    h = hashlib.sha256(f"{python}\0{abi}\0{' '.join([*cc, *CFLAGS])}".encode())
    h.update(_package_digest())
    return h.hexdigest()[:24]


@functools.cache
def _package_digest() -> bytes:
    """Every file of this gtecat, read once per process (a multi-card or 32-bit build asks
    for the libgts build below it too)."""
    h = hashlib.sha256()
    root = Path(__file__).resolve().parent.parent
    for path in sorted(root.rglob("*")):
        if "__pycache__" not in path.parts and path.is_file():
            h.update(str(path.relative_to(root)).encode() + b"\0" + path.read_bytes())
    return h.digest()


def _remember(known: Path, digest: str) -> None:
    """Write the inputs' name -> build folder, atomically (builders may run side by side)."""
    with contextlib.suppress(OSError):
        known.parent.mkdir(parents=True, exist_ok=True)
        tmp = known.with_name(f".{known.name}.{os.getpid()}")
        tmp.write_text(digest, encoding="utf-8")
        os.replace(tmp, known)


def _compile(build: Build, files: dict[str, str], cc: list[str]) -> None:
    tmp = Path(tempfile.mkdtemp(prefix=".build-", dir=build.root.parent))
    try:
        src, inc, lib = tmp / "src", tmp / "include", tmp / "lib"
        for d in (src, inc, lib):
            d.mkdir()
        for name, text in files.items():
            if name == "base":
                continue
            target = inc / name if name in INCLUDE_FILES else src / name
            target.write_text(text, encoding="utf-8")
        inside = [f"-I{inc}", f"-I{src}"]
        link: list[str] = ["-ldl"]  # (the in-process controller loads the Python runtime)
        # units compiled side by side: the transport optimised; the emulated functions'
        # stubs (each copies its arguments into an array and calls the transport) and the
        # ~3,800 one-line declared-only functions not: they have nothing to optimise, and
        # -O0 takes a quarter to a third of the time (without the asynchronous unwind
        # tables, which only a debugger walking through them would read, a third less)
        units = [
            (["gts_runtime.c"], CFLAGS),
            (["gts_stubs.c"], (*CFLAGS, *STUB_CFLAGS)),
            *(([name], flags) for name, flags in declared_units(cc)),
        ]
        if build.base is not None:  # libgts_mc: one unit over libgts
            units = [(["gts_multicard.c"], (*CFLAGS, *STUB_CFLAGS))]
            link = [*build.base.libs(), "-ldl"]
        objs = compile_units(
            [(name, flags) for names, flags in units for name in names],
            [*cc, *inside],
            src,
            "libgts",
        )
        cmd = [
            *cc,
            *CFLAGS,
            "-shared",
            f"-Wl,-soname,{build.library.name}",
            *objs,
            *link,
            "-o",
            str(lib / build.library.name),
        ]
        r = subprocess.run(cmd, capture_output=True, text=True)
        _check(cmd, r.returncode, r.stderr)
        built = lib / build.library.name
        flush(built)
        seal(built)  # (its seal goes with it: the folder is renamed into place whole)
        if build.root.exists():  # (a process with the old library mapped keeps it)
            old = Path(tempfile.mkdtemp(prefix=".build-old-", dir=build.root.parent))
            build.root.rename(old / "build")
            shutil.rmtree(old, ignore_errors=True)
        tmp.rename(build.root)
    finally:
        with contextlib.suppress(OSError):
            shutil.rmtree(tmp)


def compile_units(
    units: list[tuple[str, tuple[str, ...]]], base: list[str], folder: Path, what: str
) -> list[str]:
    """Compile each ``(source, flags)`` of ``folder`` into its object beside it, side by
    side (``base``: the compiler and the flags every unit takes); the objects' paths.
    NativeBuildError naming ``what`` when a unit fails or warns (a warning is a defect of
    the generated sources)."""
    procs = []
    for name, flags in units:
        obj = folder / (name.rsplit(".", 1)[0] + ".o")
        cmd = [*base, *flags, "-c", str(folder / name), "-o", str(obj)]
        procs.append((cmd, obj, subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True)))
    errors = []
    for cmd, _, proc in procs:
        _, err = proc.communicate()
        if proc.returncode != 0 or err.strip():
            word = "failed" if proc.returncode else "warned (it must not)"
            errors.append(f"building {what} {word} ({shlex.join(cmd)}):\n{err.strip()}")
    if errors:
        raise NativeBuildError(errors[0])
    return [str(obj) for _, obj, _ in procs]


def _check(cmd: list[str], returncode: int, stderr: str) -> None:
    if returncode != 0:
        raise NativeBuildError(f"building libgts failed ({shlex.join(cmd)}):\n{stderr.strip()}")
    if stderr.strip():
        raise NativeBuildError(f"building libgts warned (it must not):\n{stderr.strip()}")


__all__ = [
    "Build",
    "NativeBuildError",
    "cache_root",
    "compile_units",
    "compiler",
    "ensure_built",
    "multicard_sources",
    "python_executable",
    "sources",
]
