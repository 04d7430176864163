"""Building a C part in a process of its own (gtecat/cbuild.py ``Background``): the library is
named as a build in this process would name it, a refused flag falls back to the next build,
a failure says why, and the build finishes after the process that started it has ended."""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from gtecat import cbuild, cparts

ROOT = Path(__file__).resolve().parents[2]
SOURCE = "int f(void) { return 1; }\n"


def _cc(tmp_path: Path, body: str) -> Path:
    """A compiler: a shell script that logs its arguments and runs ``body``; ``$out`` is
    its ``-o`` file."""
    log = tmp_path / "cc.log"
    cc = tmp_path / "fake-cc"
    cc.write_text(
        "#!/bin/sh\n"
        f'echo "$@" >> "{log}"\n'
        'out=""; for a in "$@"; do [ "$prev" = -o ] && out="$a"; prev="$a"; done\n'
        f"{body}\n"
    )
    cc.chmod(0o755)
    return cc


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    if sys.platform == "win32":
        pytest.skip("the fake compiler is a POSIX shell script")
    monkeypatch.setenv("GTECAT_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache"


def test_builds_into_the_cache_under_the_name_of_a_build_here(
    tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("CC", str(_cc(tmp_path, 'echo built > "$out"')))
    job = ("part", SOURCE, ("-O3",), ("-lm",))
    b = cbuild.Background([job])
    assert b.wait() == cbuild.library_path(*job)
    assert b.done() and b.wait().read_text() == "built\n"
    assert [p.name for p in b.wait().parent.iterdir() if p.name.startswith(".build")] == []
    again = cbuild.Background([job])  # there already: nothing started
    assert again.done() and again.wait() == b.wait()
    assert len((tmp_path / "cc.log").read_text().splitlines()) == 1


def test_refused_flags_get_the_next_build_and_a_failure_says_why(
    tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    refuse = 'case "$*" in *-O3*) echo "cc: error: bad -O3" >&2; exit 1;; esac\necho ok > "$out"'
    monkeypatch.setenv("CC", str(_cc(tmp_path, refuse)))
    plain = ("part", SOURCE, ("-O2",), ())
    b = cbuild.Background([("part", SOURCE, ("-O3",), ()), plain])
    assert b.wait() == cbuild.library_path(*plain)
    monkeypatch.setenv("CC", str(_cc(tmp_path, 'echo "cc: error: no such file" >&2; exit 1')))
    b = cbuild.Background([("other", SOURCE, ("-O3",), ())])
    with pytest.raises(cbuild.NativeBuildError, match="no such file"):
        b.wait()
    assert b.done() and isinstance(b.result, cbuild.NativeBuildError)


def test_the_build_outlives_the_process_that_started_it(
    tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cc = _cc(tmp_path, 'sleep 0.3; echo late > "$out"')
    program = (
        "from gtecat import cbuild\n"
        f"b = cbuild.Background([('part', {SOURCE!r}, (), ())])\n"
        "print(b.libs[0])\n"
    )
    env = {**os.environ, "CC": str(cc), "PYTHONPATH": str(ROOT), "GTECAT_CACHE_DIR": str(cache)}
    r = subprocess.run(
        [sys.executable, "-W", "error", "-c", program],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.returncode == 0 and not r.stderr, r.stderr  # no warning of a child left running
    lib = Path(r.stdout.strip())
    assert not lib.exists()  # the process ended first
    end = time.monotonic() + 30
    while not lib.exists() and time.monotonic() < end:
        time.sleep(0.05)
    assert lib.read_text() == "late\n"


def _leftovers(cache: Path) -> list[str]:
    return sorted(p.name for p in cache.rglob(".build-*"))


@pytest.mark.parametrize("how", ["background", "in process"])
def test_a_killed_builder_leaves_nothing_behind_for_the_next_build(
    tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch, how: str
) -> None:
    """kill -9 of a build on the way (the OOM killer, a reboot) left its build folder and its
    log in the cache for good: the next build removes them, never a live build's."""
    import fcntl
    import signal

    slow = _cc(tmp_path, 'sleep 30; echo late > "$out"')
    call = (
        "print(cbuild.Background([('part', SRC, (), ())])._proc.pid, flush=True)"
        if how == "background"
        else "print(0, flush=True); cbuild.shared_library('part', SRC, (), ())"
    )
    program = f"from gtecat import cbuild\nSRC = {SOURCE!r}\n{call}\nimport time\ntime.sleep(60)\n"
    env = {**os.environ, "CC": str(slow), "PYTHONPATH": str(ROOT), "GTECAT_CACHE_DIR": str(cache)}
    proc = subprocess.Popen(
        [sys.executable, "-c", program],
        env=env,
        stdout=subprocess.PIPE,
        text=True,
        start_new_session=True,  # (killed with its compiler below)
    )
    builder = 0
    try:
        assert proc.stdout is not None
        builder = int(proc.stdout.readline())  # the background builder's session
        vdir = cbuild.version_dir()
        end = time.monotonic() + 30
        while not list(vdir.glob(".build-*/part*.c")) and time.monotonic() < end:
            time.sleep(0.02)
        assert len(_leftovers(cache)) == 2  # the folder and its owner file
    finally:
        for group in (proc.pid, builder):
            if group:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(group, signal.SIGKILL)
        proc.wait()
    assert len(_leftovers(cache)) == 2  # what the killed build left
    (log,) = vdir.glob(".build-*.log")
    end = time.monotonic() + 30
    while cbuild._owner_alive(log) and time.monotonic() < end:
        time.sleep(0.02)  # (the kill takes effect a moment later)
    # a live build beside it: a folder whose owner file is locked
    live = vdir / ".build-live"
    live.mkdir()
    with open(vdir / ".build-live.log", "wb") as owner:
        fcntl.flock(owner, fcntl.LOCK_EX)
        monkeypatch.setenv("CC", str(_cc(tmp_path, 'echo built > "$out"')))
        assert cbuild.Background([("other", SOURCE, (), ())]).wait().read_text() == "built\n"
        assert _leftovers(cache) == [".build-live", ".build-live.log"]
    assert cbuild.sweep(vdir) == [live, vdir / ".build-live.log"]  # its owner is gone now
    assert _leftovers(cache) == []


@pytest.fixture
def prebuilt(tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty folder of the package's prebuilt parts (gtecat/cparts.py), in place of the
    package's own."""
    folder = tmp_path / "prebuilt"
    folder.mkdir()
    monkeypatch.setattr(cbuild, "PREBUILT", folder)
    return folder


def _prebuild(folder: Path, cc: list[str], job: tuple, content: bytes = b"prebuilt") -> Path:
    """A part of ``job`` (stem, source, flags, libs) as the wheel's build leaves it."""
    lib = folder / cbuild.library_name(job[0], job[1], cc, job[2], job[3])
    lib.write_bytes(content)
    cbuild.seal(lib)
    (folder / cparts.COMPILER_FILE).write_text(" ".join(cc) + "\n")
    return lib


def test_a_prebuilt_part_of_the_same_build_is_taken_and_nothing_is_compiled(
    tmp_path: Path, prebuilt: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    cc = _cc(tmp_path, 'echo built > "$out"')
    monkeypatch.setenv("CC", str(cc))
    job = ("part", SOURCE, ("-O3",), ("-lm",))
    lib = _prebuild(prebuilt, [str(cc)], job)
    assert cbuild.found(*job) == lib and cbuild.shared_library(*job) == lib
    b = cbuild.Background([job])
    assert b.done() and b.wait() == lib and b._proc is None
    assert not (tmp_path / "cc.log").exists()  # the compiler never ran
    assert not cbuild.library_path(*job).exists()


def test_a_prebuilt_part_of_another_source_or_flags_is_never_taken(
    tmp_path: Path, prebuilt: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A source changed since the wheel was built (an editable checkout) has another name."""
    cc = _cc(tmp_path, 'echo built > "$out"')
    monkeypatch.setenv("CC", str(cc))
    _prebuild(prebuilt, [str(cc)], ("part", SOURCE, ("-O3",), ()))
    changed = ("part", SOURCE + "int g(void) { return 2; }\n", ("-O3",), ())
    assert cbuild.found(*changed) is None
    assert cbuild.shared_library(*changed) == cbuild.library_path(*changed)
    other_flags = ("part", SOURCE, ("-O2",), ())
    assert cbuild.Background([other_flags]).wait() == cbuild.library_path(*other_flags)
    assert len((tmp_path / "cc.log").read_text().splitlines()) == 2


def test_a_damaged_prebuilt_part_is_left_alone_and_built_into_the_cache(
    tmp_path: Path,
    prebuilt: Path,
    monkeypatch: pytest.MonkeyPatch,
    caplog: pytest.LogCaptureFixture,
) -> None:
    cc = _cc(tmp_path, 'echo built > "$out"')
    monkeypatch.setenv("CC", str(cc))
    job = ("part", SOURCE, ("-O3",), ())
    lib = _prebuild(prebuilt, [str(cc)], job, b"a whole library")
    lib.write_bytes(b"a whole")  # cut short, its seal kept
    with caplog.at_level("WARNING", logger="gtecat.cbuild"):
        assert cbuild.shared_library(*job) == cbuild.library_path(*job)
        assert cbuild.found(*job) == cbuild.library_path(*job)  # (asked again: no new warning)
    assert caplog.text.count("built with the package, fails its check") == 1
    assert cbuild.library_path(*job).read_text() == "built\n"
    unsealed = ("unsealed", SOURCE, ("-O3",), ())
    _prebuild(prebuilt, [str(cc)], unsealed)
    cbuild.seal_path(prebuilt / cbuild.library_path(*unsealed).name).unlink()
    assert cbuild.Background([unsealed]).wait() == cbuild.library_path(*unsealed)


def test_without_a_compiler_the_prebuilt_parts_are_found_by_the_name_their_compiler_gives(
    tmp_path: Path, prebuilt: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))
    job = ("part", SOURCE, ("-O3",), ())
    lib = _prebuild(prebuilt, ["cc"], job)
    assert cbuild.found(*job) == lib and cbuild.shared_library(*job) == lib
    assert cbuild.Background([job]).wait() == lib
    assert cbuild.found("part", SOURCE, ("-O2",), ()) is None
    with pytest.raises(cbuild.NativeBuildError, match="no C compiler"):
        cbuild.shared_library("part", SOURCE, ("-O2",), ())
    (prebuilt / cparts.COMPILER_FILE).unlink()  # (a folder without it: nothing is taken)
    assert cbuild.found(*job) is None


def test_a_source_tree_takes_the_installed_copys_part_of_the_same_build(
    tmp_path: Path, cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A checkout run beside ``pip install .`` of it (the README's test command: its tests
    import the tree's gtecat, which has no prebuilt folder) takes the installed
    distribution's part of the same name, and only that: another source is compiled."""
    installed = tmp_path / "site" / "gtecat" / "_prebuilt"
    installed.mkdir(parents=True)
    # (the checkout's folder first on the path, as from a checkout: no parts there)
    monkeypatch.setattr(sys, "path", ["", str(tmp_path / "tree"), str(tmp_path / "site")])
    monkeypatch.setattr(cbuild, "PREBUILT", tmp_path / "tree" / "_prebuilt")  # (none)
    monkeypatch.setattr(cbuild, "_INSTALLED", [])
    cc = _cc(tmp_path, 'echo built > "$out"')
    monkeypatch.setenv("CC", str(cc))
    job = ("part", SOURCE, ("-O3",), ())
    lib = _prebuild(installed, [str(cc)], job)
    assert cbuild.found(*job) == lib and cbuild.shared_library(*job) == lib
    assert not (tmp_path / "cc.log").exists()
    changed = ("part", SOURCE + "int g(void) { return 2; }\n", ("-O3",), ())
    assert cbuild.shared_library(*changed) == cbuild.library_path(*changed)
    assert len((tmp_path / "cc.log").read_text().splitlines()) == 1
    # (the tree's own folder, where there is one, is the only one looked in)
    monkeypatch.setattr(cbuild, "PREBUILT", installed.parent / "empty")
    (installed.parent / "empty").mkdir()
    assert cbuild.found(*job) is None
