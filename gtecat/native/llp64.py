"""``libgts-llp64.so``: libgts for programs written for Windows' 32-bit ``long``.

A C# or VB.NET program declares the vendor's C ``long`` as ``int`` (``out int pSts``),
``unsigned long`` as ``uint`` (``out uint pClock``): 4 bytes, as ``long`` is on Windows
(the LLP64 data model).  ``libgts.so`` follows Linux (LP64), where ``long`` has 8 bytes:
a ``long *`` output would write 8 bytes into the program's 4-byte ``int``.  This build
is the same library with every ``long`` parameter spelled ``int`` (``unsigned long`` ->
``unsigned int``) and a hello that tells the controller ``sizeof(long) = 4``, so the
controller sizes every ``long *`` at 4 bytes for this client.  Structures need nothing:
their 32-bit fields are ``int`` in both builds (:mod:`gtecat.native.cdecl`).

It is compiled on first use beside ``libgts.so`` in the same cache folder
(:func:`ensure_built`), so a changed table rebuilds both.  The Mono dllmap of
:mod:`gtecat.native.csharp` points ``gts.dll`` here.

The older multi-card ABI (:mod:`gtecat.native.multicard`, ``short cardNum`` first) has its
LLP64 build too, ``libgts_mc-llp64.so`` (``ensure_built(abi="gts-multicard")``): the same
generated layer with ``long`` -> ``int``, linked to ``libgts-llp64.so`` instead of
``libgts.so`` and compiled beside ``libgts_mc.so``.  Its ``dlsym(RTLD_NEXT)`` finds each
``GT_x`` in ``libgts-llp64.so`` (the library it needs), so a C# wrapper in the multi-card
style (``GT_GetSts(short cardNum, short axis, out int pSts, ...)``) meets 4-byte ``long``
all the way down.

``gtecat lib --m32`` builds the same LLP64 sources as a 32-bit x86 library
(``-m32 -malign-double``: ``long`` and pointers of 4 bytes, doubles aligned to 8 as the
vendor's Windows compilers align them) into a folder of its own (``m32/lib/libgts.so``,
``m32/include/gts.h``): a program compiled on Linux against the vendor's **own** header,
whose structures hold ``long`` fields (``THomePrm``), then has the structure layouts of the
Windows program it was written as (:func:`ensure_built_m32`).  It needs a 32-bit C library
(Debian's ``gcc-multilib``).
"""

from __future__ import annotations

import contextlib
import fcntl
import re
import shlex
import shutil
import subprocess
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from ..cbuild import NativeBuildError, compiler, damaged, intact, put_in_place
from . import build as _build

LIBRARY = "libgts-llp64.so"
#: the LLP64 build of the multi-card layer, over :data:`LIBRARY`
MULTICARD_LIBRARY = "libgts_mc-llp64.so"

# ``long`` that is not half of ``long long``; ``unsigned long`` first so it becomes
# ``unsigned int`` in one piece
_UNSIGNED_LONG = re.compile(r"\bunsigned long\b(?! long)")
_LONG = re.compile(r"(?<!long )\blong\b(?! long)")


def to_llp64(c_text: str) -> str:
    """A C declaration with Windows' 32-bit ``long``: ``long`` -> ``int`` (``long long``
    stays)."""
    return _LONG.sub("int", _UNSIGNED_LONG.sub("unsigned int", c_text))


def llp64_header(text: str) -> str:
    """``gts.h`` with ``int`` for ``long`` in its prototypes (structures keep their types)."""
    return "\n".join(
        to_llp64(line) if line.startswith("short ") else line for line in text.splitlines()
    )


def llp64_sources(files: dict[str, str]) -> dict[str, str]:
    """The files of the LLP64 build from libgts's: the prototypes of ``gts.h``, the stubs
    (signatures and the element sizes of their pointers) and the declared-only functions
    take ``int`` for ``long``;
    the runtime is unchanged (it keeps its own ``long`` for its own numbers)."""
    out = dict(files)
    out["gts.h"] = llp64_header(files["gts.h"])
    out["gts_stubs.c"] = to_llp64(files["gts_stubs.c"])
    out["gts_declared.c"] = to_llp64(files["gts_declared.c"])
    return out


def library(build: _build.Build) -> Path:
    return build.lib_dir / LIBRARY


def ensure_built(*, force: bool = False, abi: str = "") -> Path:
    """``libgts-llp64.so`` for this gtecat, compiled beside ``libgts.so`` if needed
    (``abi="gts-multicard"``: ``libgts_mc-llp64.so``, beside ``libgts_mc.so``)."""
    if abi:
        return _ensure_multicard(force=force, abi=abi)
    build = _build.ensure_built(force=force)
    target = library(build)
    if intact(target) and not force:
        return target
    with open(build.root.parent / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if intact(target) and not force:
            return target
        damaged(target)
        _compile(build, target)
    return target


def _ensure_multicard(*, force: bool, abi: str) -> Path:
    # libgts_mc's folder (it names the same table); forced, this compiles libgts again too,
    # which empties libgts's folder, so libgts-llp64.so is asked for after it, unforced
    build = _build.ensure_built(force=force, abi=abi)
    base = ensure_built()  # libgts-llp64.so, the library the layer calls
    target = build.lib_dir / MULTICARD_LIBRARY
    if intact(target) and not force:
        return target
    with open(build.root.parent / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if intact(target) and not force:
            return target
        damaged(target)
        _compile_multicard(build, base, target)
    return target


def multicard_sources() -> dict[str, str]:
    """The files of ``libgts_mc-llp64.so``: libgts_mc's with ``long`` -> ``int`` in its
    layer and in the single-card header it includes."""
    files = _build.multicard_sources()
    out = dict(files)
    out["gts_sc.h"] = llp64_header(files["gts_sc.h"])
    out["gts_multicard.c"] = to_llp64(files["gts_multicard.c"])
    return out


def _compile_multicard(build: _build.Build, base: Path, target: Path) -> None:
    files = multicard_sources()
    with _scratch(build) as tmp:
        for name, text in files.items():
            (tmp / name).write_text(text, encoding="utf-8")
        out = tmp / MULTICARD_LIBRARY
        cmd = [
            *compiler(),
            *_build.CFLAGS,
            "-O0",  # one-line forwarders, as libgts_mc's
            "-shared",
            f"-Wl,-soname,{MULTICARD_LIBRARY}",
            f"-I{tmp}",
            str(tmp / "gts_multicard.c"),
            f"-L{base.parent}",
            f"-Wl,-rpath,{base.parent}",
            f"-l:{base.name}",
            "-ldl",
            "-o",
            str(out),
        ]
        _run(cmd, MULTICARD_LIBRARY)
        put_in_place(out, target)


@contextlib.contextmanager
def _scratch(build: _build.Build) -> Iterator[Path]:
    tmp = Path(tempfile.mkdtemp(prefix=".llp64-", dir=build.root))
    try:
        yield tmp
    finally:
        with contextlib.suppress(OSError):
            shutil.rmtree(tmp)


def _run(cmd: list[str], what: str) -> None:
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise NativeBuildError(f"building {what} failed ({shlex.join(cmd)}):\n{r.stderr.strip()}")
    if r.stderr.strip():
        raise NativeBuildError(f"building {what} warned (it must not):\n{r.stderr.strip()}")


#: the flags of a 32-bit program with the vendor's Windows layouts (:func:`ensure_built_m32`)
M32_FLAGS = ("-m32", "-malign-double")


@dataclass(frozen=True)
class M32Build:
    """The 32-bit library's folder: ``include`` (gts.h, gtecat_vendor.h) and ``lib``."""

    root: Path

    @property
    def include_dir(self) -> Path:
        return self.root / "include"

    @property
    def library(self) -> Path:
        return self.root / "lib" / "libgts.so"

    def cflags(self) -> list[str]:
        inc = self.include_dir
        return [*M32_FLAGS, f"-I{inc}", "-include", str(inc / _build.VENDOR_COMPAT)]

    def libs(self) -> list[str]:
        lib = self.library.parent
        return ["-m32", f"-L{lib}", f"-Wl,-rpath,{lib}", "-lgts"]


def ensure_built_m32(*, force: bool = False) -> M32Build:
    """The 32-bit libgts (module docstring), compiled on first use beside libgts."""
    build = _build.ensure_built(force=force)
    m32 = M32Build(build.root / "m32")
    if intact(m32.library) and not force:
        return m32
    with open(build.root.parent / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if intact(m32.library) and not force:
            return m32
        damaged(m32.library)
        files = llp64_sources(_build.sources(_build.python_executable()))
        m32.include_dir.mkdir(parents=True, exist_ok=True)
        m32.library.parent.mkdir(parents=True, exist_ok=True)
        for name in ("gts.h", _build.VENDOR_COMPAT):
            (m32.include_dir / name).write_text(files[name], encoding="utf-8")
        _compile(build, m32.library, files, M32_FLAGS, "libgts.so")
    return m32


def _compile(
    build: _build.Build,
    target: Path,
    files: dict[str, str] | None = None,
    extra: tuple[str, ...] = (),
    soname: str = LIBRARY,
) -> None:
    cc = compiler()
    if files is None:
        files = llp64_sources(_build.sources(_build.python_executable()))
    with _scratch(build) as tmp:
        for name, text in files.items():
            (tmp / name).write_text(text, encoding="utf-8")
        out = tmp / soname
        # as libgts's units: the transport optimised, the stubs (they only pack arguments
        # for a socket round trip) and the declared-only functions at -O0 without unwind
        # tables (a third of -O1's compile time; a test run builds this once)
        base = [*cc, *extra, f"-I{tmp}"]
        runtime = ("gts_runtime.c", _build.CFLAGS)
        units = [
            ("gts_stubs.c", (*_build.CFLAGS, *_build.STUB_CFLAGS)),
            *_build.declared_units(cc, extra),
        ]
        what = soname if not extra else f"the 32-bit {soname} ({' '.join(extra)})"
        # the transport of libgts's own build serves this one unchanged: the client's long
        # size is the stubs' (gte_client_long_size) and the transport declares nothing with
        # a long, so its object is the same byte for byte (half a second of compiling); the
        # 32-bit build compiles its own, and so does one whose link refuses that object
        shared = build.root / "src" / "gts_runtime.o"
        if extra or not shared.is_file():
            units.insert(0, runtime)
        objs = _build.compile_units(units, base, tmp, what)
        if runtime not in units:
            objs.insert(0, str(shared))

        def link() -> None:
            cmd = [*cc, *extra, *_build.CFLAGS, "-shared", f"-Wl,-soname,{soname}", *objs]
            _run([*cmd, "-o", str(out)], what)

        try:
            link()
        except NativeBuildError:
            if runtime in units:
                raise
            objs[0] = _build.compile_units([runtime], base, tmp, what)[0]
            link()
        put_in_place(out, target)


__all__ = [
    "LIBRARY",
    "M32_FLAGS",
    "MULTICARD_LIBRARY",
    "M32Build",
    "ensure_built",
    "ensure_built_m32",
    "library",
    "llp64_sources",
    "multicard_sources",
    "to_llp64",
]
