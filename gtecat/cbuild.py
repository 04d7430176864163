"""Compiling the package's small C parts on first use, into a per-version cache.

``pip install`` needs no C compiler: libgts (:mod:`gtecat.native.build`), the axis bank's
compiled cycle (:mod:`gtecat.controller.bank_kernel`) and the GT fast path's pointer check
(:mod:`gtecat.gt.byref_target`) are built when first asked for, with
``$CC`` (else ``cc``, ``gcc``, ``clang``), into ``$GTECAT_CACHE_DIR`` (else
``$XDG_CACHE_HOME/gtecat``, else ``~/.cache/gtecat``) ``/<version>/``.  Here are the pieces
they share: where the cache is, which compiler, and a one-file shared library build named by
the digest of its source and flags (a lock file serialises concurrent builders), in this
process (:func:`shared_library`) or in one of its own that outlives it (:class:`Background`).
"""

from __future__ import annotations

import atexit
import hashlib
import json
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import warnings
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


def library_path(stem: str, source: str, cflags: tuple[str, ...], libs: tuple[str, ...]) -> Path:
    """``<cache>/<version>/<stem>-<digest>.so``: where the build of the one C file ``source``
    (text) with this compiler and these flags is kept (NativeBuildError without a compiler)."""
    cc = compiler()
    h = hashlib.sha256(source.encode())
    h.update(" ".join([*cc, *cflags, *libs]).encode())
    return cache_root() / __version__ / f"{stem}-{h.hexdigest()[:12]}.so"


def shared_library(stem: str, source: str, cflags: tuple[str, ...], libs: tuple[str, ...]) -> Path:
    """:func:`library_path`, built there now unless an existing build of the same source,
    compiler and flags is there."""
    cc = compiler()
    lib = library_path(stem, source, cflags, libs)
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


#: the builder process of :class:`Background` (``python -I -S -c``: no site, no gtecat):
#: argv[1] is a JSON list of (command, its output, the library's name) tried in turn until
#: one builds; the first that does is renamed to its name; the lock serialises builders and
#: a library already there ends the work; what failed goes to stderr (the parent's log file,
#: removed here when the library is there)
_BUILDER = r"""
import json, os, shutil, subprocess, sys
spec = json.loads(sys.argv[1])
try:
    os.nice(10)  # background work: the process that asked for it goes first
except (AttributeError, OSError):
    pass
try:
    import fcntl
except ImportError:
    fcntl = None
built = False
try:
    with open(spec["lock"], "w") as lock:
        if fcntl is not None:
            fcntl.flock(lock, fcntl.LOCK_EX)
        for cmd, out, lib in spec["jobs"]:
            if os.path.isfile(lib):
                built = True
                break
            try:
                r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
            except (OSError, subprocess.TimeoutExpired) as e:
                sys.stderr.write(f"{' '.join(cmd)}: {e}\n")
                continue
            if r.returncode == 0 and not r.stderr.strip():
                os.replace(out, lib)
                built = True
                break
            sys.stderr.write(f"building failed ({' '.join(cmd)}):\n{r.stderr}\n")
finally:
    if built:  # else the log says why (the parent reads it)
        try:
            os.unlink(spec["log"])
        except OSError:
            pass
    shutil.rmtree(spec["tmp"], ignore_errors=True)
"""


class Background:
    """Shared libraries built by a process of their own, while this one goes on.

    ``builds``: (stem, source, cflags, libs) tried in turn (a plain build after one whose
    flags the compiler refuses) until one builds, as :func:`shared_library` would build them.
    The builder is a small Python process (no site packages, not gtecat) in a session of its
    own, at a lower priority (nice 10: on a busy machine the work that asked for it goes
    first): it finishes and names the library even when this process ends first, and the next
    process finds it.  :meth:`done` is cheap to ask every cycle; :attr:`result` is then the
    library built (the first of ``builds`` that is there), or the NativeBuildError saying why
    not."""

    def __init__(self, builds: list[tuple[str, str, tuple[str, ...], tuple[str, ...]]]) -> None:
        self.result: Path | NativeBuildError | None = None
        self.libs = [library_path(*b) for b in builds]
        self._proc: subprocess.Popen[bytes] | None = None
        if any(lib.is_file() for lib in self.libs):
            self._finish()
            return
        cc = compiler()
        vdir = version_dir()
        tmp = Path(tempfile.mkdtemp(prefix=".build-", dir=vdir))
        jobs = []
        for k, ((stem, source, cflags, libs), lib) in enumerate(
            zip(builds, self.libs, strict=True)
        ):
            src = tmp / f"{stem}-{k}.c"
            src.write_text(source, encoding="utf-8")
            out = tmp / lib.name
            jobs.append(
                ([*cc, *cflags, "-shared", str(src), "-o", str(out), *libs], str(out), str(lib))
            )
        self._log = tmp.with_suffix(".log")
        spec = {"lock": str(vdir / ".lock"), "tmp": str(tmp), "jobs": jobs, "log": str(self._log)}
        with open(self._log, "wb") as err:
            self._proc = subprocess.Popen(
                [sys.executable, "-I", "-S", "-c", _BUILDER, json.dumps(spec)],
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=err,
                start_new_session=True,  # an interrupt of this process leaves the build be
                close_fds=True,
            )
        atexit.register(self._leave)

    def done(self) -> bool:
        """The build ended (:attr:`result` is set)."""
        if self.result is not None:
            return True
        if self._proc is None or self._proc.poll() is None:
            return False
        self._finish()
        return True

    def wait(self) -> Path:
        """The library, once built (NativeBuildError when it was not)."""
        if self._proc is not None and self.result is None:
            self._proc.wait()
            self._finish()
        result = self.result
        if isinstance(result, NativeBuildError):
            raise result
        assert result is not None
        return result

    def _leave(self) -> None:
        """At exit: a build still running goes on by itself (not a leaked child to warn of)."""
        if self._proc is not None and self._proc.poll() is None:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", ResourceWarning)
                self._proc = None

    def _finish(self) -> None:
        built = next((lib for lib in self.libs if lib.is_file()), None)
        if built is not None:
            self.result = built
        else:
            why = ""
            if self._proc is not None:
                try:
                    why = self._log.read_text(errors="replace").strip()
                except OSError:
                    pass
            self.result = NativeBuildError(why or f"{self.libs[0].name} was not built")
        if self._proc is not None:
            try:
                self._log.unlink()
            except OSError:
                pass
