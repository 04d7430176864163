"""Shared pieces of the native tests: compilers (a missing one is a skip with its reason)."""

from __future__ import annotations

import fcntl
import hashlib
import os
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from gtecat.native import header
from tests.conftest import is_setting

needs_cc = pytest.mark.skipif(
    shutil.which("gcc") is None, reason="no C compiler (gcc) on PATH: the C tests cannot run"
)
needs_cxx = pytest.mark.skipif(
    shutil.which("g++") is None, reason="no C++ compiler (g++) on PATH: the C++ tests cannot run"
)


@pytest.fixture
def gts_h(tmp_path: Path) -> Path:
    """A freshly generated gts.h in a directory of its own."""
    d = tmp_path / "include"
    d.mkdir()
    path = d / "gts.h"
    path.write_text(header.render(), encoding="utf-8")
    return path


ROOT = Path(__file__).resolve().parents[3]
FIG5_2 = ROOT / "examples" / "manual_fig5_2.eni"
C_DIR = Path(__file__).resolve().parent / "c"


def built(what: str, build):
    """``build()``'s library: with no C compiler a skip that says so; with one, a library
    that does not build is a failure (it is what users get), never a skip."""
    from gtecat.native.build import NativeBuildError

    if shutil.which("cc") is None and shutil.which("gcc") is None:
        pytest.skip(f"no C compiler (cc, gcc) on PATH: {what} cannot be built here")
    try:
        return build()
    except NativeBuildError as e:
        pytest.fail(f"{what} does not build: {e}")


@pytest.fixture(scope="session")
def libgts():
    """The built library."""
    from gtecat.native.build import ensure_built

    return built("libgts", ensure_built)


def tool_path() -> str:
    """PATH with this interpreter's directory first, so ``python3`` is the one with gtecat."""
    return os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])


def tool_pythonpath() -> str:
    """PYTHONPATH with this checkout first: ``python3 -m gtecat`` in a child (``lib --cflags``,
    the private controller a program starts) is the gtecat under test, never another
    checkout an editable install points at (a library built from this tree's stubs talking
    to another tree's controller fails in ways that have nothing to do with the test)."""
    return os.pathsep.join([str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])


def tool_env() -> dict[str, str]:
    """The environment of ``python3 -m gtecat lib`` as a user runs it in a shell (PATH and
    PYTHONPATH above), with GTECAT_PYTHON naming the interpreter the ``libgts`` fixture's
    build was made for (this one, unless the setting names another): a library is built per
    interpreter, and the ``python3`` on PATH may be another name of this one (a run started
    as ``python -m pytest``, as CI does, or by the ``pytest`` script), for which the command
    built a second libgts beside the fixture's (over a second of a first run)."""
    from gtecat.native.build import python_executable

    return {
        **os.environ,
        "PATH": tool_path(),
        "PYTHONPATH": tool_pythonpath(),
        "GTECAT_PYTHON": python_executable(),
    }


def native_env(**extra: str) -> dict[str, str]:
    """The environment of a native client: the manual's figure 5-2 bus, auto clock, no
    controller named (the library starts its own)."""
    env = {k: v for k, v in os.environ.items() if not is_setting(k)}
    env.update(PATH=tool_path(), PYTHONPATH=tool_pythonpath())
    env.update(GTECAT_ENI=str(FIG5_2), GTECAT_CLOCK="auto", GTECAT_LOG="")
    env.update(extra)
    return env


#: lib_flags's answers, by its arguments and environment
_LIB_FLAGS: dict[tuple[str, tuple[tuple[str, str], ...]], list[str]] = {}


def lib_flags(args: str = "--cflags --libs") -> list[str]:
    """The words ``python3 -m gtecat lib ARGS`` prints, as a shell's ``$(...)`` splits them:
    the command runs once per run and environment (:func:`tool_env`), and every program
    compiled after the first takes its answer (a Python process less per program)."""
    env = tool_env()
    # (the environment but pytest's name of the test running, which changes at every test)
    key = (args, tuple(sorted((k, v) for k, v in env.items() if k != "PYTEST_CURRENT_TEST")))
    if key not in _LIB_FLAGS:
        cmd = f"python3 -m gtecat lib {args}"
        r = subprocess.run(["bash", "-c", cmd], capture_output=True, text=True, env=env)
        assert r.returncode == 0, f"{cmd}\n{r.stderr}"
        assert "warning" not in r.stderr, r.stderr
        _LIB_FLAGS[key] = r.stdout.split()
    return _LIB_FLAGS[key]


def compile_client(src: Path, out: Path, compiler: str) -> Path:
    """Compile exactly as a user would: ``gcc prog.c $(python3 -m gtecat lib --cflags --libs)``
    (the command's words from :func:`lib_flags`)."""
    cmd = [*shlex.split(compiler), str(src), *lib_flags(), "-o", str(out)]
    r = subprocess.run(cmd, capture_output=True, text=True, env=tool_env())
    assert r.returncode == 0, f"{shlex.join(cmd)}\n{r.stderr}"
    assert "warning" not in r.stderr, r.stderr
    return out


@pytest.fixture(scope="session")
def motion_demo(libgts, tmp_path_factory) -> Path:
    """examples/native/motion_demo.cpp compiled once per test run (``compile_client``, so as a
    user compiles it) and shared by the tests that run it, xdist workers included."""
    return compiled_once(
        tmp_path_factory, libgts, ROOT / "examples" / "native" / "motion_demo.cpp", "g++"
    )


@pytest.fixture(scope="session")
def gtn_sequence(libgts, tmp_path_factory) -> Path:
    """c/gtn_sequence.c (the vendor's GTN sequence) compiled once for the run: the C client,
    in-process and Windows tests run it."""
    return compiled_once(tmp_path_factory, libgts, C_DIR / "gtn_sequence.c", "gcc")


@pytest.fixture(scope="session")
def gtn_sequence_on_its_controller_process(gtn_sequence, tmp_path_factory):
    """gtn_sequence run once with ``GTECAT_INPROCESS=0`` (the private controller as a process
    of its own, as a program gets it where the Python runtime cannot be loaded), in a folder
    of its own: ``(result, its lines, the folder)``, read-only.  test_inprocess checks what
    the program saw, test_c_clients that its controller ended with it (one run, not two:
    a controller process's start is most of either test)."""
    cwd = tmp_path_factory.mktemp("gtn-sequence-process")
    r, v = run_client(gtn_sequence, env=native_env(GTECAT_INPROCESS="0"), cwd=cwd)
    return r, v, cwd


def compiled_once(tmp_path_factory, libgts, src: Path, compiler: str) -> Path:
    """``compile_client(src)`` done once for the whole run: the executable goes to a folder
    every xdist worker sees (the run's base temporary folder), named by the source, the
    compiler and the library it links, and a lock file makes the other workers wait for the
    first one's build instead of compiling it again."""
    base = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        base = base.parent  # shared by the workers of this run
    key = hashlib.sha256(
        src.read_bytes() + compiler.encode() + str(libgts.library).encode()
    ).hexdigest()[:12]
    folder = base / "compiled"
    folder.mkdir(exist_ok=True)
    exe = folder / f"{src.stem}-{key}"
    with open(folder / f"{exe.name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not exe.is_file():
            tmp = exe.with_name(exe.name + ".tmp")
            compile_client(src, tmp, compiler)
            tmp.rename(exe)
    return exe


def run_client(exe: Path, *args: str, env: dict[str, str], cwd: Path, timeout: float = 180):
    r = subprocess.run(
        [str(exe), *args], capture_output=True, text=True, env=env, cwd=cwd, timeout=timeout
    )
    return r, parse_lines(r.stdout)


def parse_lines(text: str) -> dict[str, str]:
    out = {}
    for line in text.splitlines():
        key, _, value = line.partition(" ")
        out[key] = value
    return out
