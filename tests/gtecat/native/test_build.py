"""Building libgts lazily, the `gtecat lib` verb, and a machine without a C compiler."""

from __future__ import annotations

import subprocess
import sys

import pytest

from gtecat.cli.main import main
from gtecat.native import build

from .conftest import needs_cc


@needs_cc
def test_lib_flags(libgts, capsys):
    assert main(["lib", "--cflags", "--libs"]) == 0
    words = capsys.readouterr().out.split()
    assert words == [
        f"-I{libgts.include_dir}",
        "-include",  # the vendor's own header compiles unchanged (gtecat_vendor.h)
        str(libgts.include_dir / "gtecat_vendor.h"),
        f"-L{libgts.lib_dir}",
        f"-Wl,-rpath,{libgts.lib_dir}",
        "-lgts",
    ]
    assert main(["lib", "--path"]) == 0
    assert capsys.readouterr().out.strip() == str(libgts.library)
    assert libgts.library.is_file()
    assert (libgts.include_dir / "gts.h").is_file()


@needs_cc
def test_the_cache_is_per_version_and_per_sources(libgts):
    from gtecat import __version__

    assert libgts.root.parent == build.cache_root() / __version__
    assert build.ensure_built().root == libgts.root  # built once


def test_a_fresh_cache_builds_on_first_use_and_only_then(tmp_path, monkeypatch):
    """A compiler that logs its calls and writes its ``-o`` file: the build runs on first use
    into the fresh cache, and not again (the real compiler's build is the ``libgts`` fixture's,
    once per run)."""
    log = tmp_path / "cc.log"
    cc = tmp_path / "logging-cc"
    cc.write_text(
        "#!/bin/sh\n"
        f'echo "$@" >> "{log}"\n'
        'while [ $# -gt 0 ]; do if [ "$1" = -o ]; then : > "$2"; fi; shift; done\n'
    )
    cc.chmod(0o755)
    monkeypatch.setenv("CC", str(cc))
    monkeypatch.setenv("GTECAT_CACHE_DIR", str(tmp_path / "cache"))
    b = build.ensure_built()
    assert b.library.is_file() and b.header.is_file()
    assert str(b.root).startswith(str(tmp_path / "cache"))
    calls = log.read_text().splitlines()
    assert any("-shared" in c for c in calls) and any("gts_runtime.c" in c for c in calls)
    from gtecat import native

    assert native.library_path() == b.library
    assert build.ensure_built().root == b.root
    assert log.read_text().splitlines() == calls  # cached: not compiled again


def test_the_llp64_build_links_libgts_compiled_transport(tmp_path, monkeypatch):
    """libgts-llp64.so (C# under Mono) links the transport's object of libgts's own build
    (the same source and flags, and the same bytes: the client's long size is the stubs'),
    and compiles its own where that link fails (a damaged cache).  A logging compiler that
    writes its ``-o`` file, and fails a link of libgts's object once BAD exists; empty
    sources (the compiler reads none)."""
    from gtecat.native import llp64

    log, bad = tmp_path / "cc.log", tmp_path / "BAD"
    cc = tmp_path / "logging-cc"
    cc.write_text(
        "#!/bin/sh\n"
        f'echo "$@" >> "{log}"\n'
        f'case "$*" in *-shared*/src/gts_runtime.o*) [ -e "{bad}" ] && exit 1;; esac\n'
        'while [ $# -gt 0 ]; do if [ "$1" = -o ]; then : > "$2"; fi; shift; done\n'
    )
    cc.chmod(0o755)
    monkeypatch.setenv("CC", str(cc))
    b = build.Build(tmp_path / "build")
    shared = b.root / "src" / "gts_runtime.o"  # libgts's build keeps its objects there
    shared.parent.mkdir(parents=True)
    shared.touch()
    b.lib_dir.mkdir()
    files = dict.fromkeys(("gts.h", "gts_runtime.c", "gts_stubs.c", "gts_declared.c"), "")
    target = b.lib_dir / llp64.LIBRARY

    def calls() -> tuple[list[list[str]], list[int], list[int]]:
        made = [c.split() for c in log.read_text().splitlines()]
        log.write_text("")
        links = [n for n, c in enumerate(made) if "-shared" in c]
        runtime = [n for n, c in enumerate(made) if "-c" in c and "gts_runtime.c" in c[-3]]
        return made, links, runtime

    llp64._compile(b, target, files)
    made, links, runtime = calls()
    assert not runtime and len(links) == 1 and str(shared) in made[links[0]]
    assert target.is_file()
    bad.touch()
    llp64._compile(b, target, files)
    made, links, runtime = calls()
    assert len(links) == 2 and str(shared) in made[links[0]]  # refused: compiled here
    assert len(runtime) == 1 and links[0] < runtime[0] < links[1]
    assert str(shared) not in made[links[1]] and target.is_file()


def test_no_compiler_is_a_clear_error(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("CC", str(tmp_path / "no-cc"))
    monkeypatch.setenv("GTECAT_CACHE_DIR", str(tmp_path / "cache"))
    with pytest.raises(build.NativeBuildError, match="not found"):
        build.ensure_built()
    assert main(["lib", "--cflags"]) == 1
    assert "error:" in capsys.readouterr().err
    monkeypatch.delenv("CC")
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(build.NativeBuildError, match="no C compiler"):
        build.ensure_built()


def test_the_header_prints_without_a_build(capsys):
    assert main(["lib", "--header"]) == 0
    assert "short GT_GetSts(short axis, long *pSts" in capsys.readouterr().out


@pytest.mark.long
def test_importing_gtecat_needs_no_compiler(tmp_path):
    """pip install works without cc: nothing is compiled until the library is asked for."""
    code = "import gtecat.native, gtecat.native.server, gtecat.gt; print('ok')"
    r = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        env={"PATH": str(tmp_path), "GTECAT_CACHE_DIR": str(tmp_path / "c")},
    )
    assert r.stdout.strip() == "ok", r.stderr
    # (the cache keeps Python's own work - compiled code, the parsed function table - but no
    # C library and no build of one)
    cache = tmp_path / "c"
    assert not [f for f in cache.rglob("*") if f.suffix in (".so", ".dll", ".c", ".o")]
    assert not list(cache.rglob(".build-*"))


def test_csrc_is_package_data():
    import tomllib
    from pathlib import Path

    root = Path(__file__).resolve().parents[3]
    cfg = tomllib.loads((root / "pyproject.toml").read_text())
    assert "native/csrc/*" in cfg["tool"]["setuptools"]["package-data"]["gtecat"]


def test_every_declared_only_function_names_itself_and_answers_8(libgts):
    """Each declared-only export of libgts (the assembled ones on x86-64 Linux, the C
    bodies elsewhere) reaches ``gte_declared`` with its own table index and face: called
    with no controller it answers 8 and ``GTE_GetLastError`` names that very function."""
    import ctypes

    from gtecat.native.protocol import plans

    lib = ctypes.CDLL(str(libgts.library))
    lib.GTE_GetLastError.argtypes = [ctypes.c_char_p, ctypes.c_short]
    buf = ctypes.create_string_buffer(512)
    names = []
    for p in plans():
        if p.declared:
            names += [p.name, p.proto.twin_name] if p.proto.gtn else [p.name]
    assert len(names) > 3000
    wrong = []
    for name in names:
        fn = getattr(lib, name)
        fn.restype = ctypes.c_short
        rc = fn()
        lib.GTE_GetLastError(buf, len(buf))
        if rc != 8 or not buf.value.decode().startswith(f"{name} returned 8: {name} is declared"):
            wrong.append((name, rc, buf.value.decode()))
    assert not wrong, wrong[:5]
    assert build.declared_units(build.compiler())  # the units of this machine's build
