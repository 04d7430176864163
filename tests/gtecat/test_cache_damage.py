"""A damaged library in the build cache (gtecat/cbuild.py's seals): a library cut short (a
disk that filled up, a copy of the cache that broke off) is found before it is loaded and
built again, where loading it would kill the process with SIGBUS and no message.

The real libraries are not compiled anew here: the "compiler" of these tests copies the
library the test process already has (byref_target, the bank kernel), so the process under
test loads a real one after the rebuild."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from importlib import resources
from pathlib import Path

import pytest

from gtecat import __version__, cbuild

pytestmark = pytest.mark.skipif(
    sys.platform == "win32", reason="the copying compiler is a POSIX shell script"
)

ROOT = Path(__file__).resolve().parents[2]


def _cut(lib: Path) -> None:
    """Cut ``lib`` to half its size (what a full disk or a broken copy leaves), its seal
    kept."""
    data = lib.read_bytes()
    lib.write_bytes(data[: len(data) // 2])


def _real_libraries() -> dict[str, tuple[Path, tuple[str, str, tuple[str, ...], tuple[str, ...]]]]:
    """stem -> (an intact library of this machine's compiler, its build job)."""
    if shutil.which("cc") is None and shutil.which("gcc") is None and not os.environ.get("CC"):
        pytest.skip("no C compiler (cc, gcc) on PATH: no library to damage")
    from gtecat.controller import bank_kernel
    from gtecat.gt import byref_target

    jobs = {
        "byref_target": (
            "byref_target",
            (resources.files("gtecat.gt") / "csrc" / "byref_target.c").read_text("utf-8"),
            byref_target.CFLAGS,
            (),
        ),
        "bank_kernel": ("bank_kernel", bank_kernel._source(), bank_kernel.CFLAGS, ("-lm",)),
    }
    # (built once per cache: the test process has byref_target already)
    return {stem: (cbuild.shared_library(*job), job) for stem, job in jobs.items()}


@pytest.fixture(scope="module")
def damaged_cache(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, dict]:
    """A private cache holding both libraries cut short under the names a build with the
    copying compiler gives them, and that compiler."""
    real = _real_libraries()
    tmp = tmp_path_factory.mktemp("damaged")
    cc = tmp / "copying-cc"
    cases = "".join(f'  *{stem}*) src="{lib}";;\n' for stem, (lib, _) in real.items())
    cc.write_text(
        "#!/bin/sh\n"
        'out=""; for a in "$@"; do [ "$prev" = -o ] && out="$a"; prev="$a"; done\n'
        f'case "$*" in\n{cases}esac\n'
        'cp "$src" "$out"\n'
    )
    cc.chmod(0o755)
    cache = tmp / "cache"
    # the GT function table as the test process has it cached (not read anew there)
    table = cbuild.cache_root() / __version__ / "table"
    if table.is_dir():
        shutil.copytree(table, cache / __version__ / "table")
    env = {**os.environ, "GTECAT_CACHE_DIR": str(cache), "CC": str(cc)}
    old = {k: os.environ.get(k) for k in ("GTECAT_CACHE_DIR", "CC")}
    os.environ.update(GTECAT_CACHE_DIR=env["GTECAT_CACHE_DIR"], CC=env["CC"])
    try:
        names = {}
        for stem, (lib, job) in real.items():
            target = cbuild.library_path(*job)
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(lib, target)
            cbuild.seal(target)
            _cut(target)
            names[stem] = target
    finally:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
    return cache, cc, {"env": env, "libs": names, "real": {s: r[0] for s, r in real.items()}}


def test_cut_short_libraries_are_built_again_and_the_process_works(damaged_cache) -> None:
    """``from gtecat import gt`` (byref_target at import) and the bank kernel's load, in a
    process of their own over the damaged cache: no SIGBUS, a warning each, the C paths in
    use, and intact libraries in the cache afterwards."""
    _, _, d = damaged_cache
    for lib in d["libs"].values():
        assert not cbuild.intact(lib)
    code = (
        "import json\n"
        "from gtecat import gt\n"
        "from gtecat.gt import byref_target\n"
        "from gtecat.controller import bank_kernel\n"
        "lib, why = bank_kernel.library()\n"
        "print(json.dumps([byref_target.REASON, lib is not None, why]))\n"
    )
    r = subprocess.run(
        [sys.executable, "-c", code], env=d["env"], capture_output=True, text=True, timeout=120
    )
    assert r.returncode == 0, (r.returncode, r.stderr)
    assert json.loads(r.stdout) == ["", True, ""]
    for stem, lib in d["libs"].items():
        assert f"{lib.name} in the build cache fails its check" in r.stderr
        assert cbuild.intact(lib), stem
        assert lib.read_bytes() == d["real"][stem].read_bytes()


def test_a_background_build_replaces_a_cut_short_library(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """The builder process of its own (the bank kernel's build beside the bus) does not take
    a library that fails its check for a built one."""
    log = tmp_path / "cc.log"
    cc = tmp_path / "cc"
    cc.write_text(
        "#!/bin/sh\n"
        f'echo "$@" >> "{log}"\n'
        'out=""; for a in "$@"; do [ "$prev" = -o ] && out="$a"; prev="$a"; done\n'
        'printf "built whole" > "$out"\n'
    )
    cc.chmod(0o755)
    monkeypatch.setenv("CC", str(cc))
    monkeypatch.setenv("GTECAT_CACHE_DIR", str(tmp_path / "cache"))
    job = ("part", "int f(void) { return 1; }\n", ("-O2",), ())
    lib = cbuild.Background([job]).wait()
    assert cbuild.intact(lib) and lib.read_bytes() == b"built whole"
    _cut(lib)
    with caplog.at_level("WARNING", "gtecat.cbuild"):
        again = cbuild.Background([job])
    assert "5 bytes, built as 11" in caplog.text
    assert again.wait() == lib and cbuild.intact(lib) and lib.read_bytes() == b"built whole"
    assert len(log.read_text().splitlines()) == 2


def test_the_check_finds_every_kind_of_damage(tmp_path: Path) -> None:
    lib = tmp_path / "x.so"
    assert cbuild._flaw(lib) == "not there"
    lib.write_bytes(b"\x7fELF" + bytes(60))
    assert cbuild._flaw(lib) == "not sealed"  # (built before seals: rebuilt, with a note)
    cbuild.seal(lib)
    assert cbuild.intact(lib)
    lib.write_bytes(b"\x7fELF" + bytes(59) + b"\1")  # same size, one byte changed
    assert cbuild._flaw(lib) == "its content changed since it was built"
    lib.write_bytes(b"\x7fELF")
    assert cbuild._flaw(lib) == "4 bytes, built as 64"
    cbuild.seal_path(lib).write_text("garbage")
    assert cbuild._flaw(lib) == "its seal is damaged"
    out = tmp_path / "out.so"
    out.write_bytes(b"new")
    cbuild.put_in_place(out, lib)
    assert not out.exists() and cbuild.intact(lib) and lib.read_bytes() == b"new"


def test_a_damaged_libgts_is_built_again(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """libgts (``gtecat lib``, ``gtecat.native.cdll()``): a library cut short in its build
    folder is built again, the folder replaced whole."""
    from gtecat.native import build

    log = tmp_path / "cc.log"
    cc = tmp_path / "cc"
    cc.write_text(
        "#!/bin/sh\n"
        f'echo "$@" >> "{log}"\n'
        'while [ $# -gt 0 ]; do if [ "$1" = -o ]; then printf "libgts" > "$2"; fi; shift; done\n'
    )
    cc.chmod(0o755)
    monkeypatch.setenv("CC", str(cc))
    monkeypatch.setenv("GTECAT_CACHE_DIR", str(tmp_path / "cache"))
    b = build.ensure_built()
    assert cbuild.intact(b.library) and b.library.read_bytes() == b"libgts"

    def links() -> int:
        return sum("-shared" in c for c in log.read_text().splitlines())

    assert build.ensure_built().root == b.root
    assert links() == 1  # intact: not built again
    _cut(b.library)
    assert build.ensure_built().root == b.root
    assert links() == 2
    assert cbuild.intact(b.library) and b.library.read_bytes() == b"libgts"
    assert [p.name for p in b.root.parent.iterdir() if p.name.startswith(".build")] == []
