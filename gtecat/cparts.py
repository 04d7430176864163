"""The package's small C parts as the wheel's build and a first use both see them.

A C part (:mod:`gtecat.cbuild`) is one file ``csrc/<stem>.c`` built into a shared library
named ``<stem>-<digest>.so``, where the digest covers the source, the compiler command and the
flags: the same name means the same build.  Where ``pip install .`` builds the wheel and
finds a C compiler, it builds the parts a program's first run would otherwise compile (the
list :data:`PARTS`) into the package's ``_prebuilt/`` folder under those very names, each
sealed as the cache seals its own (:func:`seal`); a first use takes an intact one whose
name is the name of the build it wants (:func:`gtecat.cbuild.found`) before it builds.  A
source changed since (an editable checkout) has another digest: its old build is never
taken.

Nothing here imports gtecat or anything outside the standard library: the wheel's build
(``setup.py``) loads this file by its path in pip's build environment, where gtecat's
dependencies (numpy...) are not installed.
"""

from __future__ import annotations

import hashlib
import os
import shutil
from pathlib import Path

# (shlex, subprocess, tempfile and the thread pool are imported where a build or an unusual
# lookup needs them: a process whose parts are built never does)

#: flags of the GT fast path's pointer check (:mod:`gtecat.gt.byref_target`) and its C entry
#: (:mod:`gtecat.gt.centry`): -O1, not the bank kernel's -O3 - both are call glue (argument
#: checks, a few loads and stores, no loops worth unrolling), as fast at -O1 (GT_GetSts,
#: GT_EcatIOReadInput, GTE_Wait's entries within 1-2 % of -O2; -O0 costs 20-30 %) and half
#: the compiler's time, which a new install's first import waits for where nothing is prebuilt
GT_CFLAGS = ("-std=c99", "-O1", "-fPIC", "-Wall", "-Wextra")
#: the axis bank's C units (:mod:`gtecat.controller.bank_kernel`): IEEE arithmetic exactly as
#: written: no contraction into FMA, no fast-math (-O3 changes no value: it reorders no
#: floating-point operation without -ffast-math's licences); portable code for any processor
#: of the architecture (no -march: the cache may be shared between machines, and an
#: instruction set chosen per processor measured no faster)
BANK_CFLAGS = ("-std=c99", "-O3", "-fPIC", "-Wall", "-Wextra", "-ffp-contract=off")
#: the bank's plain build, when the compiler refuses BANK_CFLAGS
BANK_PLAIN_CFLAGS = ("-std=c99", "-O2", "-fPIC", "-Wall", "-Wextra", "-ffp-contract=off")

#: (package, stem, the flags tried in turn, libraries) of every part the wheel's build
#: prebuilds, the longest compiles first: what a bring-up and a first motion compile (the GT
#: entries at import, the bank's cycle once the bus is in OP), and the bank's smaller units
#: (coordinate systems, PVT, the slaves' images: a tenth of a second each).  libgts is not
#: among them: it is built for a C program that asks for it, with the interpreter it embeds
#: (:mod:`gtecat.native.build`)
PARTS: tuple[tuple[str, str, tuple[tuple[str, ...], ...], tuple[str, ...]], ...] = (
    ("gtecat.controller", "bank_kernel", (BANK_CFLAGS, BANK_PLAIN_CFLAGS), ("-lm",)),
    ("gtecat.gt", "centry", (GT_CFLAGS,), ()),
    ("gtecat.gt", "byref_target", (GT_CFLAGS,), ()),
    ("gtecat.controller", "bank_crd", (BANK_CFLAGS, BANK_PLAIN_CFLAGS), ("-lm",)),
    ("gtecat.controller", "bank_pvt", (BANK_CFLAGS, BANK_PLAIN_CFLAGS), ("-lm",)),
    ("gtecat.controller", "bank_slaves", (BANK_CFLAGS, BANK_PLAIN_CFLAGS), ()),
)

#: the folder of the package's prebuilt parts (absent where none were built: an editable
#: install, a wheel built without a compiler)
PREBUILT = Path(__file__).parent / "_prebuilt"
#: the file in :data:`PREBUILT` naming the compiler command that built them (JSON-free: one
#: shell-quoted line), so a machine without a compiler still finds them by name
COMPILER_FILE = "compiler"
#: the first word of a seal (:func:`seal`)
SEAL = "gtecat-library-1"


def find_compiler() -> tuple[list[str] | None, str]:
    """The C compiler command (``$CC``, else ``cc``, ``gcc``, ``clang`` on PATH), or None
    and why there is none."""
    cc = os.environ.get("CC")
    if cc:
        import shlex

        cmd = shlex.split(cc)
        if cmd and shutil.which(cmd[0]):
            return cmd, ""
        return None, f"CC={cc!r}: {cmd[0] if cmd else cc!r} not found on PATH"
    for name in ("cc", "gcc", "clang"):
        if shutil.which(name):
            return [name], ""
    return None, (
        "no C compiler (cc, gcc or clang on PATH, or set CC): libgts cannot be built; "
        "the Python API (from gtecat import gt) works without it"
    )


def library_name(
    stem: str, source: str, cc: list[str], cflags: tuple[str, ...], libs: tuple[str, ...]
) -> str:
    """``<stem>-<digest>.so``: the name of the build of the one C file ``source`` (text) with
    compiler command ``cc`` and these flags."""
    h = hashlib.sha256(source.encode())
    h.update(" ".join([*cc, *cflags, *libs]).encode())
    return f"{stem}-{h.hexdigest()[:12]}.so"


def prebuilt_compiler(folder: Path = PREBUILT) -> list[str] | None:
    """The compiler command that built the parts in ``folder`` (None: nothing built there)."""
    try:
        text = (folder / COMPILER_FILE).read_text(encoding="utf-8")
    except OSError:
        return None
    import shlex

    return shlex.split(text)


def source_path(root: Path, package: str, stem: str) -> Path:
    """``csrc/<stem>.c`` of gtecat package ``package`` (``"gtecat.gt"``) under the folder
    ``root`` that holds the ``gtecat`` folder."""
    return root.joinpath(*package.split("."), "csrc", f"{stem}.c")


def seal_path(lib: Path) -> Path:
    """The seal of library ``lib``: ``<lib>.ok``."""
    return lib.with_name(lib.name + ".ok")


def digest_file(path: Path) -> str:
    """The SHA-256 of file ``path`` (hex)."""
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


def flush(path: Path) -> None:
    """Write ``path``'s data to the disk (before it is renamed into place: a power cut
    then leaves the old name or the whole file, not a short one)."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    except OSError:
        pass  # (a file system without fsync: the rename alone)
    finally:
        os.close(fd)


def seal(lib: Path) -> None:
    """Record the size and SHA-256 of library ``lib`` (complete, in place) in its seal,
    written under another name and renamed; call it under the build lock."""
    st = lib.stat()
    text = f"{SEAL} {st.st_size} {digest_file(lib)}\n"
    ok = seal_path(lib)
    tmp = ok.with_name(f".{ok.name}.{os.getpid()}")
    tmp.write_text(text, encoding="ascii")
    os.replace(tmp, ok)


def compile_command(
    cc: list[str], cflags: tuple[str, ...], src: Path, out: Path, libs: tuple[str, ...]
) -> list[str]:
    """The command that builds the shared library ``out`` of the one C file ``src``."""
    return [*cc, *cflags, "-shared", str(src), "-o", str(out), *libs]


def run_compiler(cmd: list[str], timeout: float = 120) -> str:
    """Run a compile: '' when it built cleanly, else why not (its error output; a warning
    counts as a failure, as the parts compile without one)."""
    import shlex
    import subprocess

    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return f"{shlex.join(cmd)} ran {timeout:g} s"
    except OSError as e:
        return f"{shlex.join(cmd)}: {e}"
    if r.returncode != 0 or r.stderr.strip():
        return r.stderr.strip() or f"{shlex.join(cmd)} exited with {r.returncode}"
    return ""


def prebuild(root: Path, dest: Path, cc: list[str], jobs: int = 2) -> list[str]:
    """Build every part of :data:`PARTS` whose source is under ``root`` (the folder that
    holds the ``gtecat`` folder) into ``dest`` (emptied first) with compiler command ``cc``,
    each under its :func:`library_name` and sealed, ``jobs`` compiles at a time; returns
    what failed (a part that does not build is left out: a first use builds it).  The
    wheel's build (``setup.py``) calls it."""
    import shlex
    import tempfile
    from concurrent.futures import ThreadPoolExecutor

    shutil.rmtree(dest, ignore_errors=True)
    dest.mkdir(parents=True)
    (dest / COMPILER_FILE).write_text(shlex.join(cc) + "\n", encoding="utf-8")
    with tempfile.TemporaryDirectory(prefix="gtecat-prebuild-") as tmp:

        def one(part: tuple[str, str, tuple[tuple[str, ...], ...], tuple[str, ...]]) -> str:
            package, stem, variants, libs = part
            src = source_path(root, package, stem)
            try:
                source = src.read_text("utf-8")
            except OSError as e:
                return f"{stem}: {e}"
            why = ""
            for k, cflags in enumerate(variants):
                name = library_name(stem, source, cc, cflags, libs)
                out = Path(tmp) / f"{k}-{name}"
                why = run_compiler(compile_command(cc, cflags, src, out, libs))
                if not why:
                    lib = dest / name
                    os.replace(out, lib)
                    seal(lib)
                    return ""
            return f"{stem}: {why}"

        with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
            failed = [why for why in pool.map(one, PARTS) if why]
    return failed
