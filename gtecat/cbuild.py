"""Compiling the package's small C parts on first use, into a per-version cache.

``pip install`` needs no C compiler: libgts (:mod:`gtecat.native.build`), the axis bank's
compiled cycle (:mod:`gtecat.controller.bank_kernel`) and the GT fast path's pointer check
(:mod:`gtecat.gt.byref_target`) are built when first asked for, with
``$CC`` (else ``cc``, ``gcc``, ``clang``), into ``$GTECAT_CACHE_DIR`` (else
``$XDG_CACHE_HOME/gtecat``, else ``~/.cache/gtecat``) ``/<version>/``.  Here are the pieces
they share: where the cache is, which compiler, and a one-file shared library build named by
the digest of its source and flags (a lock file serialises concurrent builders).
"""

from __future__ import annotations

import hashlib
import os
import shlex
import shutil
import subprocess
import tempfile
from pathlib import Path

from . import __version__
from ._cache import cache_root
from .errors import GtecatError

try:
    import fcntl
except ImportError:  # Windows: a controller runs there without these builds' lock
    fcntl = None  # type: ignore[assignment]


class NativeBuildError(GtecatError):
    """A C part could not be built (no compiler, a compile error); the Python API is unaffected."""


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


def version_dir() -> Path:
    """This version's build cache, created (NativeBuildError when it cannot be)."""
    d = cache_root() / __version__
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise NativeBuildError(f"cannot create the build cache {d}: {e}") from None
    return d


def shared_library(stem: str, source: str, cflags: tuple[str, ...], libs: tuple[str, ...]) -> Path:
    """``<cache>/<version>/<stem>-<digest>.so`` built from the one C file ``source`` (text);
    an existing build of the same source, compiler and flags is reused."""
    cc = compiler()
    h = hashlib.sha256(source.encode())
    h.update(" ".join([*cc, *cflags, *libs]).encode())
    lib = cache_root() / __version__ / f"{stem}-{h.hexdigest()[:12]}.so"
    if lib.is_file():
        return lib
    vdir = version_dir()
    with open(vdir / ".lock", "w") as lock:
        if fcntl is not None:
            fcntl.flock(lock, fcntl.LOCK_EX)
        if lib.is_file():
            return lib
        tmp = Path(tempfile.mkdtemp(prefix=".build-", dir=vdir))
        try:
            src = tmp / f"{stem}.c"
            src.write_text(source, encoding="utf-8")
            out = tmp / lib.name
            cmd = [*cc, *cflags, "-shared", str(src), "-o", str(out), *libs]
            try:
                r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
            except subprocess.TimeoutExpired:
                raise NativeBuildError(f"building {stem}: {shlex.join(cmd)} ran 120 s") from None
            if r.returncode != 0 or r.stderr.strip():
                raise NativeBuildError(f"building {stem} failed ({shlex.join(cmd)}):\n{r.stderr}")
            out.rename(lib)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
    return lib
