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
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import re
import shlex
import shutil
import subprocess
import tempfile
from pathlib import Path

from ..cbuild import NativeBuildError, compiler
from . import build as _build

LIBRARY = "libgts-llp64.so"

# ``long`` that is not half of ``long long``; ``unsigned long`` first so it becomes
# ``unsigned int`` in one piece
_UNSIGNED_LONG = re.compile(r"\bunsigned long\b(?! long)")
_LONG = re.compile(r"(?<!long )\blong\b(?! long)")


def to_llp64(c_text: str) -> str:
    """A C declaration with Windows' 32-bit ``long``: ``long`` -> ``int`` (``long long``
    stays)."""
    return _LONG.sub("int", _UNSIGNED_LONG.sub("unsigned int", c_text))


def llp64_sources(files: dict[str, str]) -> dict[str, str]:
    """The files of the LLP64 build from libgts's: the prototypes of ``gts.h``, the stubs
    (signatures and the element sizes of their pointers) and the declared-only functions
    take ``int`` for ``long``;
    the runtime is unchanged (it keeps its own ``long`` for its own numbers)."""
    out = dict(files)
    out["gts.h"] = "\n".join(
        to_llp64(line) if line.startswith("short ") else line
        for line in files["gts.h"].splitlines()
    )
    out["gts_stubs.c"] = to_llp64(files["gts_stubs.c"])
    out["gts_declared.c"] = to_llp64(files["gts_declared.c"])
    return out


def library(build: _build.Build) -> Path:
    return build.lib_dir / LIBRARY


def ensure_built(*, force: bool = False) -> Path:
    """``libgts-llp64.so`` for this gtecat, compiled beside ``libgts.so`` if needed."""
    build = _build.ensure_built(force=force)
    target = library(build)
    if target.is_file() and not force:
        return target
    with open(build.root.parent / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if target.is_file() and not force:
            return target
        _compile(build, target)
    return target


def _compile(build: _build.Build, target: Path) -> None:
    cc = compiler()
    files = llp64_sources(_build.sources(_build.python_executable()))
    tmp = Path(tempfile.mkdtemp(prefix=".llp64-", dir=build.root))
    try:
        for name, text in files.items():
            (tmp / name).write_text(text, encoding="utf-8")
        out = tmp / LIBRARY
        # -O1, not libgts's -O2: the stubs only pack arguments for a socket round trip, and
        # it halves the compile (a test run builds this once)
        flags = [f for f in _build.CFLAGS if not f.startswith("-O")] + ["-O1"]
        cmd = [
            *cc,
            *flags,
            "-DGTE_CLIENT_LONG_SIZE=4",
            "-shared",
            f"-Wl,-soname,{LIBRARY}",
            f"-I{tmp}",
            str(tmp / "gts_runtime.c"),
            str(tmp / "gts_stubs.c"),
            str(tmp / "gts_declared.c"),  # the declared-only functions
            "-o",
            str(out),
        ]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            raise NativeBuildError(
                f"building {LIBRARY} failed ({shlex.join(cmd)}):\n{r.stderr.strip()}"
            )
        if r.stderr.strip():
            raise NativeBuildError(f"building {LIBRARY} warned (it must not):\n{r.stderr.strip()}")
        os.replace(out, target)
    finally:
        with contextlib.suppress(OSError):
            shutil.rmtree(tmp)


__all__ = ["LIBRARY", "ensure_built", "library", "llp64_sources", "to_llp64"]
