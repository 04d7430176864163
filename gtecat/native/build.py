"""Build ``libgts.so`` and ``gts.h`` on first use, into a per-version cache.

``pip install`` needs no C compiler: nothing is compiled until a program asks for
the library (``python3 -m gtecat lib ...``, :func:`gtecat.native.library_path`).
The build writes the generated sources (``gts.h``, ``gts_wire.h``, ``gts_stubs.c``)
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
from ..errors import GtecatError
from . import header, stubs

RUNTIME_SOURCES = ("gts_runtime.c", "gts_runtime.h")
CFLAGS = ("-std=c99", "-O2", "-fPIC", "-Wall", "-Wextra", "-pthread")


class NativeBuildError(GtecatError):
    """libgts could not be built (no compiler, a compile error); the Python API is unaffected."""


@dataclass(frozen=True, slots=True)
class Build:
    root: Path

    @property
    def include_dir(self) -> Path:
        return self.root / "include"

    @property
    def lib_dir(self) -> Path:
        return self.root / "lib"

    @property
    def library(self) -> Path:
        return self.lib_dir / "libgts.so"

    @property
    def header(self) -> Path:
        return self.include_dir / "gts.h"

    def cflags(self) -> list[str]:
        return [f"-I{self.include_dir}"]

    def libs(self) -> list[str]:
        return [f"-L{self.lib_dir}", f"-Wl,-rpath,{self.lib_dir}", "-lgts"]


def cache_root() -> Path:
    env = os.environ.get("GTECAT_CACHE_DIR")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(xdg) if xdg else Path.home() / ".cache"
    return base / "gtecat"


def compiler() -> list[str]:
    """The C compiler command (NativeBuildError when there is none)."""
    cc = os.environ.get("CC")
    if cc:
        cmd = shlex.split(cc)
        if shutil.which(cmd[0]):
            return cmd
        raise NativeBuildError(f"CC={cc!r}: {cmd[0]} not found on PATH")
    for name in ("cc", "gcc", "clang"):
        if shutil.which(name):
            return [name]
    raise NativeBuildError(
        "no C compiler (cc, gcc or clang on PATH, or set CC): libgts cannot be built; "
        "the Python API (from gtecat import gt) works without it"
    )


def python_executable() -> str:
    """The interpreter a private controller runs on (GTECAT_PYTHON overrides at run time)."""
    return os.environ.get("GTECAT_PYTHON") or sys.executable or "python3"


def sources(python: str) -> dict[str, str]:
    """Every file of the build, by name."""
    out = {
        "gts.h": header.render(),
        "gts_wire.h": stubs.render_wire_h(),
        "gts_stubs.c": stubs.render_stubs(python),
    }
    pkg = resources.files("gtecat.native") / "csrc"
    for name in RUNTIME_SOURCES:
        out[name] = (pkg / name).read_text(encoding="utf-8")
    return out


def _digest(files: dict[str, str], cc: list[str]) -> str:
    h = hashlib.sha256()
    for name in sorted(files):
        h.update(name.encode() + b"\0" + files[name].encode() + b"\0")
    h.update(" ".join([*cc, *CFLAGS]).encode())
    return h.hexdigest()[:12]


def ensure_built(*, force: bool = False) -> Build:
    """The build for this gtecat, compiled now if it is not in the cache yet."""
    cc = compiler()
    python = python_executable()
    files = sources(python)
    version_dir = cache_root() / __version__
    build = Build(version_dir / _digest(files, cc))
    if build.library.is_file() and build.header.is_file() and not force:
        return build
    try:
        version_dir.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise NativeBuildError(f"cannot create the build cache {version_dir}: {e}") from None
    with open(version_dir / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if build.library.is_file() and build.header.is_file() and not force:
            return build
        _compile(build, files, cc)
    return build


def _compile(build: Build, files: dict[str, str], cc: list[str]) -> None:
    tmp = Path(tempfile.mkdtemp(prefix=".build-", dir=build.root.parent))
    try:
        src, inc, lib = tmp / "src", tmp / "include", tmp / "lib"
        for d in (src, inc, lib):
            d.mkdir()
        for name, text in files.items():
            target = inc / name if name == "gts.h" else src / name
            target.write_text(text, encoding="utf-8")
        cmd = [
            *cc,
            *CFLAGS,
            "-shared",
            "-Wl,-soname,libgts.so",
            f"-I{inc}",
            f"-I{src}",
            str(src / "gts_runtime.c"),
            str(src / "gts_stubs.c"),
            "-o",
            str(lib / "libgts.so"),
        ]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            raise NativeBuildError(
                f"building libgts failed ({shlex.join(cmd)}):\n{r.stderr.strip()}"
            )
        if r.stderr.strip():
            raise NativeBuildError(f"building libgts warned (it must not):\n{r.stderr.strip()}")
        if build.root.exists():
            shutil.rmtree(build.root)
        tmp.rename(build.root)
    finally:
        with contextlib.suppress(OSError):
            shutil.rmtree(tmp)


KERNEL_SOURCE = "bank_kernel.c"
#: the axis bank's kernel: IEEE arithmetic exactly as written (no contraction into FMA, no
#: fast-math), so it gives numpy's and the scalar code's bits
KERNEL_CFLAGS = ("-std=c99", "-O2", "-fPIC", "-Wall", "-Wextra", "-ffp-contract=off")


def ensure_kernel() -> Path:
    """The compiled axis-bank kernel (:mod:`gtecat.controller.bank_kernel`), built into the
    same per-version cache as libgts on first use; NativeBuildError when it cannot be."""
    cc = compiler()
    text = (resources.files("gtecat.native") / "csrc" / KERNEL_SOURCE).read_text(encoding="utf-8")
    h = hashlib.sha256(text.encode())
    h.update(" ".join([*cc, *KERNEL_CFLAGS]).encode())
    version_dir = cache_root() / __version__
    lib = version_dir / f"bank_kernel-{h.hexdigest()[:12]}.so"
    if lib.is_file():
        return lib
    try:
        version_dir.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise NativeBuildError(f"cannot create the build cache {version_dir}: {e}") from None
    with open(version_dir / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if lib.is_file():
            return lib
        tmp = Path(tempfile.mkdtemp(prefix=".build-", dir=version_dir))
        try:
            src = tmp / KERNEL_SOURCE
            src.write_text(text, encoding="utf-8")
            out = tmp / lib.name
            cmd = [*cc, *KERNEL_CFLAGS, "-shared", str(src), "-o", str(out), "-lm"]
            r = subprocess.run(cmd, capture_output=True, text=True)
            if r.returncode != 0 or r.stderr.strip():
                raise NativeBuildError(
                    f"building the bank kernel failed ({shlex.join(cmd)}):\n{r.stderr.strip()}"
                )
            out.rename(lib)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
    return lib


__all__ = [
    "Build",
    "NativeBuildError",
    "cache_root",
    "compiler",
    "ensure_built",
    "ensure_kernel",
    "python_executable",
    "sources",
]
