"""Compiling the package's small C parts where they are not built yet, into a per-version cache.

``pip install`` needs no C compiler.  Where it finds one, the wheel's build compiles the parts a
first run needs - the GT fast path's C entry (:mod:`gtecat.gt.centry`) and pointer check
(:mod:`gtecat.gt.byref_target`), the axis bank's compiled cycle and its smaller units
(:mod:`gtecat.controller.bank_kernel`) - into the package (:mod:`gtecat.cparts`), so that a
new install's first run compiles nothing.  Whatever is not there (an editable install, no
compiler at install, a source changed since, a damaged file) is built when first asked for,
as is libgts (:mod:`gtecat.native.build`), with ``$CC`` (else ``cc``, ``gcc``, ``clang``),
into ``$GTECAT_CACHE_DIR`` (else ``$XDG_CACHE_HOME/gtecat``, else ``~/.cache/gtecat``)
``/<version>/``.  Here are the pieces they share: where the cache is, which compiler, and a
one-file shared library build named by the digest of its source, compiler and flags (a lock
file serialises concurrent builders), looked for in the package (or, for a source tree
installed beside, in the installed copy), then in the cache (:func:`found`), else built in
this process (:func:`shared_library`) or in one of its own that outlives it
(:class:`Background`).

A build works in a folder ``<cache>/<version>/.build-XXXX/`` beside its owner file
``.build-XXXX.log`` (the background builder's error output), and holds a lock on that file
for as long as the build runs: the process that builds (and the background builder after
it) keeps it open.  A builder killed on the way (the OOM killer, ``kill -9``, a reboot)
leaves both behind with nobody holding the lock; every later build first removes such
leftovers (:func:`sweep`), never the folder of a build that still runs.

A library is put in place complete: built under another name, flushed to the disk, then
renamed; beside it its seal, ``<name>.ok``, records its size and SHA-256 (:func:`seal`).
Before a library is loaded :func:`intact` compares the two (a tenth of a millisecond for
these files): a library cut short (a disk that filled up, a copy of the cache that broke
off, a power cut) would otherwise crash the process that maps it, with no message.  A
library that fails the check is built again (:func:`shared_library`).  The package's own
are sealed the same way and checked the same way before they are loaded; one that fails is
never loaded (a warning each time: reinstalling mends it) and the cache's build is used.
"""

from __future__ import annotations

import atexit
import contextlib
import logging
import os
import shutil
import sys
import time
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

from . import __version__
from ._cache import cache_root
from .cparts import (
    PREBUILT,
    SEAL,
    compile_command,
    find_compiler,
    flush,
    library_name,
    prebuilt_compiler,
    run_compiler,
)
from .cparts import digest_file as _digest_file
from .cparts import seal as seal
from .cparts import seal_path as seal_path
from .errors import GtecatError

try:
    import fcntl
except ImportError:  # Windows: a controller runs there without these builds' lock
    fcntl = None  # type: ignore[assignment]


if TYPE_CHECKING:
    import subprocess

# (subprocess, shlex and json are imported where a build runs: a process whose libraries are
# built already - every process but the first - never needs them)

log = logging.getLogger(__name__)


class NativeBuildError(GtecatError):
    """A C part could not be built (no compiler, a compile error); the Python API is unaffected."""


def compiler() -> list[str]:
    """The C compiler command (NativeBuildError when there is none)."""
    cmd, why = find_compiler()
    if cmd is None:
        raise NativeBuildError(why)
    return cmd


def version_dir() -> Path:
    """This version's build cache, created (NativeBuildError when it cannot be)."""
    d = cache_root() / __version__
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise NativeBuildError(f"cannot create the build cache {d}: {e}") from None
    return d


#: a build folder without an owner file (or, where there are no file locks, any build
#: folder) is taken as left over once it is this old (seconds): no build runs that long
STALE_AGE_S = 30 * 60
_PREFIX = ".build-"


def _dirs_lock(vdir: Path) -> Any:
    """The lock under which build folders are made and leftovers removed (held briefly,
    unlike ``.lock``, which a builder holds for its whole compile); None without file locks."""
    if fcntl is None:
        return contextlib.nullcontext()
    f = open(vdir / ".dirs.lock", "w")
    fcntl.flock(f, fcntl.LOCK_EX)
    return f


def _owner_alive(log: Path) -> bool:
    """Someone holds the lock on the build's owner file (the build still runs)."""
    if fcntl is None:
        return True  # cannot tell: only the age decides
    try:
        fd = os.open(log, os.O_RDWR)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        return True
    finally:
        os.close(fd)  # (releases the lock taken just now)
    return False


def _old(path: Path, now: float) -> bool:
    try:
        return now - path.stat().st_mtime > STALE_AGE_S
    except OSError:
        return False


def sweep(vdir: Path) -> list[Path]:
    """Remove the build folders and owner files of builders that died on the way (module
    docstring); returns what was removed.  Called by every builder before it starts."""
    removed: list[Path] = []
    now = time.time()
    with _dirs_lock(vdir):
        try:
            names = [e.name for e in os.scandir(vdir) if e.name.startswith(_PREFIX)]
        except OSError:
            return removed
        for stem in sorted({n.removesuffix(".log") for n in names}):
            folder, log = vdir / stem, vdir / f"{stem}.log"
            has_log = f"{stem}.log" in names
            if has_log:
                if _owner_alive(log):
                    continue
                if (fcntl is None or not folder.exists()) and not _old(log, now):
                    continue  # (a failed build's log that its process has yet to read)
            elif not _old(folder, now):
                continue  # (a build of another kind in here, or one that just began)
            for path in (folder, log):
                if path.is_dir():
                    shutil.rmtree(path, ignore_errors=True)
                    removed.append(path)
                elif path.exists():
                    with contextlib.suppress(OSError):
                        path.unlink()
                        removed.append(path)
    return removed


class _BuildDir:
    """A build folder and its owner file, locked (module docstring); made under the folders'
    lock so that :func:`sweep` never sees it unowned."""

    def __init__(self, vdir: Path) -> None:
        import tempfile  # (here: a process whose libraries are built never imports it, ~3 ms)

        sweep(vdir)
        with _dirs_lock(vdir):
            self.path = Path(tempfile.mkdtemp(prefix=_PREFIX, dir=vdir))
            self.log = self.path.with_suffix(".log")
            self.owner = open(self.log, "wb")
            if fcntl is not None:
                fcntl.flock(self.owner, fcntl.LOCK_EX)

    def close(self) -> None:
        """Remove the folder and the owner file, then let go of the owner file's lock."""
        shutil.rmtree(self.path, ignore_errors=True)
        with contextlib.suppress(OSError):
            self.log.unlink()
        self.owner.close()


def unseal(lib: Path) -> None:
    """Remove ``lib``'s seal (before the library is replaced: no old seal for a new file)."""
    with contextlib.suppress(FileNotFoundError):
        seal_path(lib).unlink()


def put_in_place(out: Path, lib: Path) -> None:
    """Library ``out``, complete, becomes ``lib``: flushed, renamed over ``lib`` (a process
    that has the old file mapped keeps it), then sealed; call it under the build lock."""
    try:
        flush(out)
        unseal(lib)
        os.replace(out, lib)
        seal(lib)
    except OSError as e:  # (a full disk: the library is not taken, so built again next time)
        raise NativeBuildError(f"cannot put {lib.name} in the build cache: {e}") from None


def _flaw(lib: Path) -> str:
    """'' when ``lib`` is intact (:func:`intact`), else what is wrong."""
    try:
        text = seal_path(lib).read_text(encoding="ascii")
    except FileNotFoundError:
        return "not there" if not lib.exists() else "not sealed"
    except OSError as e:
        return f"its seal cannot be read ({e.strerror})"
    try:
        word, size, digest = text.split()
        want = int(size)
    except ValueError:
        return "its seal is damaged"
    try:
        got = lib.stat().st_size
        if word != SEAL:
            return "its seal is of another kind"
        if got != want:
            return f"{got} bytes, built as {want}"
        if _digest_file(lib) != digest:
            return "its content changed since it was built"
    except OSError as e:
        return f"it cannot be read ({e.strerror})"
    return ""


def intact(lib: Path) -> bool:
    """``lib`` is there, sealed, and of the size and SHA-256 its seal records: safe to load.
    False for a missing library (or seal), one cut short or otherwise changed."""
    return not _flaw(lib)


def damaged(lib: Path) -> bool:
    """``lib`` is there but fails :func:`intact` (it is then built again); logged: a warning
    for a library cut short or changed, a note for one without a seal (built before seals)."""
    if not lib.exists():
        return False
    why = _flaw(lib)
    if not why:
        return False
    level = logging.INFO if why == "not sealed" else logging.WARNING
    log.log(level, "%s in the build cache fails its check (%s): it is built again", lib, why)
    return True


def c_source(package: str, stem: str) -> str:
    """The text of the C file ``csrc/<stem>.c`` of gtecat package ``package`` (``"gtecat.gt"``),
    read from the package's folder (``importlib.resources``, whose import with zipfile's is
    ~5 ms of a process's start, only for a package that is not a folder)."""
    root = Path(__file__).parent.joinpath(*package.split(".")[1:])
    try:
        return (root / "csrc" / f"{stem}.c").read_text("utf-8")
    except OSError:
        from importlib import resources

        return (resources.files(package) / "csrc" / f"{stem}.c").read_text("utf-8")


def library_path(stem: str, source: str, cflags: tuple[str, ...], libs: tuple[str, ...]) -> Path:
    """``<cache>/<version>/<stem>-<digest>.so``: where the build of the one C file ``source``
    (text) with this compiler and these flags is kept (NativeBuildError without a compiler)."""
    return cache_root() / __version__ / library_name(stem, source, compiler(), cflags, libs)


def found(stem: str, source: str, cflags: tuple[str, ...], libs: tuple[str, ...]) -> Path | None:
    """An intact build of this source, compiler and flags that is there already: the
    package's own (built with the wheel, module docstring), else the cache's; None when
    neither is.  Without a compiler here the package's parts are looked for under the name
    the compiler that built them gives (they need none to load)."""
    cc, _ = find_compiler()
    if cc is None:
        cc = prebuilt_compiler(_prebuilt_folder())
        return None if cc is None else _prebuilt(library_name(stem, source, cc, cflags, libs))
    name = library_name(stem, source, cc, cflags, libs)
    ready = _prebuilt(name)
    if ready is None and intact(lib := cache_root() / __version__ / name):
        ready = lib
    return ready


#: the installed distribution's prebuilt parts, looked for once (see :func:`_prebuilt_folder`)
_INSTALLED: list[Path | None] = []


def _prebuilt_folder() -> Path:
    """The package's prebuilt parts: its own folder, or - where this gtecat runs from a
    source tree that has none (a checkout whose tests run beside ``pip install .`` of it,
    as the README's test command does) - the installed copy's, the first on the import
    path.  A part is taken only by its name, the digest of its source, compiler and flags,
    so one of the installed copy's serves only where this tree's source is the same: what
    it would compile."""
    if PREBUILT.is_dir():
        return PREBUILT
    if not _INSTALLED:
        # (the folders of the import path, as the installed copy is found there: a few
        # stat calls, where asking the installed distributions' metadata cost ~15 ms)
        other = None
        for entry in sys.path:
            folder = Path(entry or os.curdir, "gtecat", "_prebuilt")
            if folder.is_absolute() and folder.is_dir():
                other = folder
                break
        _INSTALLED.append(other)
    return _INSTALLED[0] or PREBUILT


#: the damaged prebuilt parts warned of in this process (once each)
_WARNED: set[Path] = set()


def _prebuilt(name: str) -> Path | None:
    """The package's build ``name`` where it is there and intact; one that fails its check
    (a damaged installation) is left alone with a warning, once per process: the cache's
    build is taken (or made, where there is a compiler; else the Python path runs)."""
    lib = _prebuilt_folder() / name
    why = _flaw(lib)
    if not why:
        return lib
    if why != "not there" and lib not in _WARNED:
        _WARNED.add(lib)
        log.warning(
            "%s, built with the package, fails its check (%s): not loaded; a build of the "
            "cache is used where there is one or a compiler can make it, else gtecat's Python "
            "path (reinstalling gtecat mends it)",
            lib,
            why,
        )
    return None


def shared_library(stem: str, source: str, cflags: tuple[str, ...], libs: tuple[str, ...]) -> Path:
    """The build of the one C file ``source`` (text) with this compiler and these flags:
    :func:`found`, else built into :func:`library_path` now."""
    ready = found(stem, source, cflags, libs)
    if ready is not None:
        return ready
    cc = compiler()
    lib = library_path(stem, source, cflags, libs)
    vdir = version_dir()
    with open(vdir / ".lock", "w") as lock:
        if fcntl is not None:
            fcntl.flock(lock, fcntl.LOCK_EX)
        if intact(lib):
            return lib
        damaged(lib)
        build = _BuildDir(vdir)
        tmp = build.path
        try:
            src = tmp / f"{stem}.c"
            src.write_text(source, encoding="utf-8")
            out = tmp / lib.name
            cmd = compile_command(cc, cflags, src, out, libs)
            why = run_compiler(cmd)
            if why:
                import shlex

                raise NativeBuildError(f"building {stem} failed ({shlex.join(cmd)}):\n{why}")
            put_in_place(out, lib)
        finally:
            build.close()
    return lib


#: the builder process of :class:`Background` (``python -I -S -c``: no site, no gtecat):
#: argv[1] is a JSON list of (command, its output, the library's name) tried in turn until
#: one builds; the first that does is flushed, renamed to its name and sealed (as
#: :func:`shared_library` does); the lock serialises builders and an intact library already
#: there ends the work; what failed goes to stderr (the parent's log file,
#: removed here when the library is there); its stderr holds the lock on that log (the
#: owner file: inherited from the parent, so the lock lasts while either of them runs)
_BUILDER = r"""
import hashlib, json, os, shutil, subprocess, sys
spec = json.loads(sys.argv[1])
SEAL = spec["seal"]
def digest(path):
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()
def intact(lib):
    try:
        with open(lib + ".ok", encoding="ascii") as f:
            word, size, sha = f.read().split()
        return word == SEAL and os.stat(lib).st_size == int(size) and digest(lib) == sha
    except (OSError, ValueError):
        return False
def put(out, lib):
    fd = os.open(out, os.O_RDONLY)
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
    try:
        os.unlink(lib + ".ok")
    except FileNotFoundError:
        pass
    os.replace(out, lib)
    tmp = f"{os.path.dirname(lib)}/.{os.path.basename(lib)}.ok.{os.getpid()}"
    with open(tmp, "w", encoding="ascii") as f:
        f.write(f"{SEAL} {os.stat(lib).st_size} {digest(lib)}\n")
    os.replace(tmp, lib + ".ok")
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
            if intact(lib):
                built = True
                break
            try:
                r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
            except (OSError, subprocess.TimeoutExpired) as e:
                sys.stderr.write(f"{' '.join(cmd)}: {e}\n")
                continue
            if r.returncode == 0 and not r.stderr.strip():
                put(out, lib)
                built = True
                break
            sys.stderr.write(f"building failed ({' '.join(cmd)}):\n{r.stderr}\n")
finally:
    shutil.rmtree(spec["tmp"], ignore_errors=True)
    if built:  # else the log says why (the parent reads it)
        try:
            os.unlink(spec["log"])
        except OSError:
            pass
"""


class Background:
    """Shared libraries built by a process of their own, while this one goes on.

    ``builds``: (stem, source, cflags, libs) tried in turn (a plain build after one whose
    flags the compiler refuses) until one builds, as :func:`shared_library` would build them.
    The builder is a small Python process (no site packages, not gtecat) in a session of its
    own, at a lower priority (nice 10: on a busy machine the work that asked for it goes
    first): it finishes and names the library even when this process ends first, and the next
    process finds it.  Where Linux groups the scheduling by session (autogroup, the default
    of most distributions), that session is a group of its own, and a task's nice orders it
    only within its group: against the process that asked, the builder then takes a whole
    group's share (with two busy loops in that process's session on two CPUs, it ran a
    third of the time instead of two thirds, for the ~3 s of the build).  The group's nice
    is left as it is on purpose: raised too, the build starved there (over 8 s) and the
    bank ran its numpy cycle all that time, which cost far more than the build's CPU.

    :meth:`done` is cheap to ask every cycle; :attr:`result` is then the
    library built (the first of ``builds`` that is there), or the NativeBuildError saying why
    not."""

    def __init__(self, builds: list[tuple[str, str, tuple[str, ...], tuple[str, ...]]]) -> None:
        self.result: Path | NativeBuildError | None = None
        self._proc: subprocess.Popen[bytes] | None = None
        built = next((lib for b in builds if (lib := found(*b)) is not None), None)
        if built is not None:  # (checked once: its seal's digest is the cost)
            self.result = built
            self.libs = [built]
            return
        self.libs = [library_path(*b) for b in builds]
        cc = compiler()
        vdir = version_dir()
        build = _BuildDir(vdir)
        tmp = build.path
        jobs = []
        for k, ((stem, source, cflags, libs), lib) in enumerate(
            zip(builds, self.libs, strict=True)
        ):
            src = tmp / f"{stem}-{k}.c"
            src.write_text(source, encoding="utf-8")
            out = tmp / lib.name
            jobs.append((compile_command(cc, cflags, src, out, libs), str(out), str(lib)))
        self._log = build.log
        for lib in self.libs:
            damaged(lib)
        spec = {
            "lock": str(vdir / ".lock"),
            "tmp": str(tmp),
            "jobs": jobs,
            "log": str(self._log),
            "seal": SEAL,
        }
        import json
        import subprocess

        try:
            self._proc = subprocess.Popen(
                [sys.executable, "-I", "-S", "-c", _BUILDER, json.dumps(spec)],
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=build.owner,  # (the owner file's lock goes with it)
                start_new_session=True,  # an interrupt of this process leaves the build be
                close_fds=True,
            )
        except BaseException:
            build.close()
            raise
        build.owner.close()  # the builder holds the lock from here on
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
        built = next((lib for lib in self.libs if intact(lib)), None)
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
