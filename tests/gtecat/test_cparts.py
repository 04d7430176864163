"""The C parts the wheel's build prebuilds (gtecat/cparts.py, setup.py): each under the name a
first use looks for, sealed; a flag the compiler refuses gets the plain build; without a
compiler, or with one that fails, the build goes on without them."""

from __future__ import annotations

import json
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


#: runs ``setup.py build_py`` (sys.argv[1]: the project) once per (CC, build folder, file for
#: its stderr) of the JSON in sys.argv[2], each run with setup.py loaded afresh, as pip's build
#: backend runs it: in the process, not in a process of its own.  Prints the exit codes.
_BUILDS = """
import json, os, runpy, sys
project, runs = sys.argv[1], json.loads(sys.argv[2])
os.chdir(project)
codes = []
for cc, lib, err in runs:
    os.environ["CC"] = cc
    sys.stderr.flush()
    fd = os.open(err, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    os.dup2(fd, 2)
    os.close(fd)
    sys.argv = ["setup.py", "-q", "build_py", "--build-lib", lib]
    try:
        runpy.run_path("setup.py", run_name="__main__")
        code = 0
    except SystemExit as e:
        if isinstance(e.code, str):
            print(e.code, file=sys.stderr)
        code = e.code if isinstance(e.code, int) else 1
    sys.stderr.flush()
    codes.append(code)
print(json.dumps(codes))
"""


@pytest.fixture(scope="module")
def builds(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[int, str, Path, str]]:
    """``setup.py build_py`` of the project (its package linked in) with ``CC`` a compiler
    that builds, none, and one that fails: (exit code, stderr, the built package, CC) each,
    read only.  One Python process runs the three builds (the third of a second of importing
    setuptools, once)."""
    tmp = tmp_path_factory.mktemp("cparts")
    project = tmp / "project"
    project.mkdir()
    for name in ("setup.py", "pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, project / name)
    (project / "gtecat").symlink_to(ROOT / "gtecat")
    for kind in ("builds", "failing"):
        (tmp / kind).mkdir()
    ccs = {
        "builds": str(_cc(tmp / "builds", 'echo built > "$out"')),
        "none": str(tmp / "no-such-cc"),
        "failing": str(_cc(tmp / "failing", 'echo "cc: error: broken" >&2; exit 1')),
    }
    runs = [(cc, str(tmp / f"lib-{kind}"), str(tmp / f"err-{kind}")) for kind, cc in ccs.items()]
    r = subprocess.run(
        [sys.executable, "-c", _BUILDS, str(project), json.dumps(runs)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stderr
    codes = json.loads(r.stdout.splitlines()[-1])
    return {
        kind: (code, Path(err).read_text(), Path(lib) / "gtecat", cc)
        for kind, code, (cc, lib, err) in zip(ccs, codes, runs, strict=True)
    }


def test_the_wheel_build_prebuilds_the_parts_beside_the_package(
    builds: dict[str, tuple[int, str, Path, str]],
) -> None:
    code, err, package, cc = builds["builds"]
    assert code == 0, err
    assert (package / "cbuild.py").is_file() and (package / "gt" / "csrc" / "centry.c").is_file()
    libs = sorted(p.name for p in (package / "_prebuilt").glob("*.so"))
    assert len(libs) == len(cparts.PARTS)
    assert all(cbuild.intact(package / "_prebuilt" / name) for name in libs)
    assert cparts.prebuilt_compiler(package / "_prebuilt") == [cc]


@pytest.mark.parametrize("cc", ["none", "failing"])
def test_the_wheel_build_goes_on_without_a_compiler_or_with_one_that_fails(
    builds: dict[str, tuple[int, str, Path, str]], cc: str
) -> None:
    """``pip install`` needs no C compiler: the parts are then built on first use."""
    code, err, package, _ = builds[cc]
    assert code == 0, err
    assert (package / "cbuild.py").is_file()
    assert not list((package / "_prebuilt").glob("*.so"))
    if cc == "failing":
        assert "a C part not prebuilt" in err and "broken" in err


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
