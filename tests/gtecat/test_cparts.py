"""The C parts the wheel's build prebuilds (gtecat/cparts.py, setup.py): each under the name a
first use looks for, sealed; a flag the compiler refuses gets the plain build; without a
compiler, or with one that fails, the build goes on without them."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from gtecat import cbuild, cparts

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="the compilers are shell scripts")

ROOT = Path(__file__).resolve().parents[2]


def _cc(tmp_path: Path, body: str) -> Path:
    """A compiler: a shell script that runs ``body``; ``$out`` is its ``-o`` file."""
    cc = tmp_path / "fake-cc"
    cc.write_text(
        "#!/bin/sh\n"
        'out=""; for a in "$@"; do [ "$prev" = -o ] && out="$a"; prev="$a"; done\n'
        f"{body}\n"
    )
    cc.chmod(0o755)
    return cc


def test_the_parts_a_first_run_builds_are_prebuilt_with_their_flags() -> None:
    """What the modules ask for at first use is what the wheel's build builds."""
    from gtecat.controller import bank_kernel, bank_pvt, bank_slaves
    from gtecat.gt import byref_target

    parts = {stem: (package, variants, libs) for package, stem, variants, libs in cparts.PARTS}
    assert parts["byref_target"] == ("gtecat.gt", (byref_target.CFLAGS,), ())
    assert parts["centry"] == ("gtecat.gt", (byref_target.CFLAGS,), ())
    bank = (bank_kernel.CFLAGS, bank_kernel.PLAIN_CFLAGS)
    assert parts["bank_kernel"] == ("gtecat.controller", bank, ("-lm",))
    assert parts["bank_crd"] == ("gtecat.controller", bank, ("-lm",))
    for unit in (bank_pvt.library, bank_slaves.library):  # (built with bank_kernel.build)
        assert parts[unit.stem] == ("gtecat.controller", bank, unit.libs)
    for package, stem, _, _ in cparts.PARTS:
        assert cparts.source_path(ROOT, package, stem).read_text("utf-8") == cbuild.c_source(
            package, stem
        )


def test_prebuild_names_and_seals_each_part_and_falls_back_to_the_plain_flags(
    tmp_path: Path,
) -> None:
    """(A compiler that refuses -O3 and -O1: the bank's parts get their plain build, the GT
    parts none.)"""
    refuse = (
        'case "$*" in *-O[13]*) echo "cc: error: bad -O" >&2; exit 1;; esac\necho "$*" > "$out"'
    )
    cc = [str(_cc(tmp_path, refuse))]
    dest = tmp_path / "_prebuilt"
    failed = cparts.prebuild(ROOT, dest, cc)
    assert cparts.prebuilt_compiler(dest) == cc
    built = {p.name for p in dest.glob("*.so")}
    for package, stem, variants, libs in cparts.PARTS:
        source = cparts.source_path(ROOT, package, stem).read_text("utf-8")
        taken = next((f for f in variants if "-O3" not in f and "-O1" not in f), None)
        if taken is None:  # (the GT parts have no plain build: left to a first use)
            assert any(why.startswith(f"{stem}: ") and "bad -O" in why for why in failed)
            continue
        name = cparts.library_name(stem, source, cc, taken, libs)
        assert name in built and cbuild.intact(dest / name)
        built.remove(name)
    assert not built and len(failed) == 2
    assert not list(tmp_path.glob("gtecat-prebuild-*"))


def _setup_build_py(tmp_path: Path, cc: str) -> tuple[subprocess.CompletedProcess[str], Path]:
    """``setup.py build_py`` of the project (its package linked in) with ``CC=cc``."""
    project = tmp_path / "project"
    project.mkdir()
    for name in ("setup.py", "pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, project / name)
    (project / "gtecat").symlink_to(ROOT / "gtecat")
    lib = tmp_path / "build-lib"
    r = subprocess.run(
        [sys.executable, "setup.py", "-q", "build_py", "--build-lib", str(lib)],
        cwd=project,
        env={**os.environ, "CC": cc},
        capture_output=True,
        text=True,
        timeout=120,
    )
    return r, lib / "gtecat"


def test_the_wheel_build_prebuilds_the_parts_beside_the_package(tmp_path: Path) -> None:
    cc = str(_cc(tmp_path, 'echo built > "$out"'))
    r, package = _setup_build_py(tmp_path, cc)
    assert r.returncode == 0, r.stderr
    assert (package / "cbuild.py").is_file() and (package / "gt" / "csrc" / "centry.c").is_file()
    libs = sorted(p.name for p in (package / "_prebuilt").glob("*.so"))
    assert len(libs) == len(cparts.PARTS)
    assert all(cbuild.intact(package / "_prebuilt" / name) for name in libs)
    assert cparts.prebuilt_compiler(package / "_prebuilt") == [cc]


@pytest.mark.parametrize("cc", ["none", "failing"])
def test_the_wheel_build_goes_on_without_a_compiler_or_with_one_that_fails(
    tmp_path: Path, cc: str
) -> None:
    """``pip install`` needs no C compiler: the parts are then built on first use."""
    command = (
        str(tmp_path / "no-such-cc")
        if cc == "none"
        else str(_cc(tmp_path, 'echo "cc: error: broken" >&2; exit 1'))
    )
    r, package = _setup_build_py(tmp_path, command)
    assert r.returncode == 0, r.stderr
    assert (package / "cbuild.py").is_file()
    assert not list((package / "_prebuilt").glob("*.so"))
    if cc == "failing":
        assert "a C part not prebuilt" in r.stderr and "broken" in r.stderr


@pytest.mark.long("a pip install of the package into a folder, its build environment fetched")
def test_a_wheel_install_runs_its_first_import_on_the_prebuilt_parts(tmp_path: Path) -> None:
    """``pip install .``: a wheel tagged for the platform, whose first import (no compiler on
    PATH, an empty cache) loads the C entry and the bank's kernel from the package."""
    if shutil.which("cc") is None:
        pytest.skip("no C compiler: the wheel has no parts")
    target = tmp_path / "site"
    r = subprocess.run(
        [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(target), "."],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr
    (wheel_info,) = target.glob("gtecat-*.dist-info")
    assert "Tag: py3-none-" in (wheel_info / "WHEEL").read_text()
    program = (
        "from gtecat.gt import centry\n"
        "from gtecat.controller import bank_kernel\n"
        "lib, why = bank_kernel.library()\n"
        "print(repr(centry.REASON), lib is not None, why)\n"
    )
    env = {
        **{k: v for k, v in os.environ.items() if k != "CC"},
        "PATH": str(tmp_path / "no-compiler"),
        "PYTHONPATH": str(target),
        "GTECAT_CACHE_DIR": str(tmp_path / "cache"),
    }
    r = subprocess.run(
        [sys.executable, "-c", program], cwd=tmp_path, env=env, capture_output=True, text=True
    )
    assert r.stdout.split() == ["''", "True"], r.stdout + r.stderr
    assert not list((tmp_path / "cache").rglob("*.so"))
