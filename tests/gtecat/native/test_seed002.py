"""Seed 002's own C++ homing class, compiled unchanged against our gts.h and run on ``gts:4``.

The seed (``../shared/seeds/002_*.txt``, a blog post) holds ``Motion.h`` and ``Motion.cpp``;
they are cut out of it here, at test time (the project does not copy them): ``Motion.h``
from ``#pragma once`` to the class's closing ``};``, ``Motion.cpp`` from
``#include "Motion.h"`` to the last ``}`` before the page's footer.  The page indents with
non-breaking spaces (HTML ``&nbsp;``), which a compiler rejects; they become plain spaces,
as a browser's copy gives them - no token changes (checked).  A ``main`` of ours calls
``Motion::init()`` and ``Motion::LimitHome(axis)`` and prints what happened.

The program runs with ``GTECAT_CARD=gts:4`` and a machine description whose axis 3 (the
seed's ``Axis_X``) has its negative limit at -50000, in a folder holding the ``GTS800.cfg``
its ``init`` loads: the vendor-written ``smarthome_test.cfg`` (the vendor's MCT) - once as
it is (axis 3's limits wired to none: the search reads the axis's own terminal) and once
with axis 3's limits wired to its terminal 3 (the two index lines MCT writes then).  The
limit homing (moveDir -1, velLow 20, homeOffset 10000) captures the limit within half a
cycle's travel at velLow (10 counts, sampled once per 1 ms cycle) and ends 10000 above it;
the seed zeroes the position there.
"""

from __future__ import annotations

import re
import shlex
import subprocess
from pathlib import Path

import pytest

from tests.conftest import SHARED_FIXTURES, needs_fixture

from .conftest import native_env, needs_cxx, tool_path

# the compiled seed program serves the module: under pytest-xdist (--dist loadgroup) one worker
pytestmark = [needs_cxx, pytest.mark.xdist_group("seed002")]

SEEDS = SHARED_FIXTURES.parent / "seeds"
NBSP = "\u00a0"
LIMIT = -50000
MAIN = r"""
#include "Motion.h"
#include <cstdio>
#include <cstdlib>

int main(int argc, char **argv)
{
    int axis = argc > 1 ? atoi(argv[1]) : 3;
    short rc = Motion::init();
    printf("init %d\n", rc);
    if (rc != 0)
        return 1;
    rc = Motion::LimitHome(Axis(axis));
    printf("home %d\n", rc);
    THomeStatus st;
    GT_GetHomeStatus(axis, &st);
    printf("status %d %d %d %d %d\n", st.run, st.stage, st.error, st.capturePos, st.targetPos);
    long sts = 0;
    GT_GetSts(axis, &sts);
    double prf = 0, enc = 0, machine = 0;
    GT_GetPrfPos(axis, &prf);
    GT_GetEncPos(axis, &enc);
    GTE_GetMachinePos(axis, &machine);
    printf("after %.0f %.0f %.0f %ld\n", prf, enc, machine, sts);
    printf("close %d\n", Motion::close());
    return rc;
}
"""


def seed_text() -> str:
    found = sorted(SEEDS.glob("002_*.txt"))
    if not found:
        pytest.skip(needs_fixture("the user's C++ homing class (Motion.h/Motion.cpp)"))
    return found[0].read_text(encoding="utf-8")


def extract(text: str) -> tuple[str, str]:
    """Motion.h and Motion.cpp as the seed prints them (module docstring)."""
    lines = text.splitlines()
    h0 = lines.index("#pragma once")
    c0 = lines.index('#include "Motion.h"')
    h1 = max(i for i in range(h0, c0) if lines[i] == "};")
    footer = next(i for i in range(c0, len(lines)) if lines[i].lstrip().startswith("•"))
    c1 = max(i for i in range(c0, footer) if lines[i] == "}")
    return "\n".join(lines[h0 : h1 + 1]) + "\n", "\n".join(lines[c0 : c1 + 1]) + "\n"


def _tokens(src: str) -> list[str]:
    return src.replace(NBSP, " ").split()


@pytest.fixture(scope="module")
def seed_program(tmp_path_factory, libgts):
    header, source = extract(seed_text())
    assert "class Motion" in header and "static short LimitHome(Axis axis);" in header
    assert "short Motion::moveHomeInner(Axis axis)" in source and "GT_GoHome" in source
    d = tmp_path_factory.mktemp("seed002")
    clean_h, clean_cpp = header.replace(NBSP, " "), source.replace(NBSP, " ")
    assert _tokens(clean_h) == _tokens(header) and _tokens(clean_cpp) == _tokens(source)
    (d / "Motion.h").write_text(clean_h, encoding="utf-8")
    (d / "Motion.cpp").write_text(clean_cpp, encoding="utf-8")
    (d / "main.cpp").write_text(MAIN, encoding="utf-8")
    exe = d / "seed002"
    flags = "$(python3 -m gtecat lib --cflags --libs)"
    cmd = f"g++ main.cpp Motion.cpp {flags} -o {shlex.quote(str(exe))}"
    r = subprocess.run(
        ["bash", "-c", cmd],
        cwd=d,
        capture_output=True,
        text=True,
        env={**native_env(), "PATH": tool_path()},
    )
    assert r.returncode == 0, f"{cmd}\n{r.stderr}"
    assert "warning" not in r.stderr, r.stderr  # const char * in gts.h: no string warnings
    return exe


def vendor_cfg(wire_axis_3: bool) -> str:
    cfg = SHARED_FIXTURES / "googol" / "smarthome_test.cfg"
    if not cfg.is_file():
        pytest.skip(needs_fixture(cfg.name))
    text = cfg.read_text(encoding="utf-8")
    if wire_axis_3:
        a, b = text.index("[axis3]"), text.index("[axis4]")
        section = text[a:b]
        for key in ("limitPositiveIndex", "limitNegativeIndex"):
            section = section.replace(f"{key}=-1", f"{key}=3")
        text = text[:a] + section + text[b:]
    return text


def run_seed(exe: Path, folder: Path, cfg: str, axis: int = 3) -> dict[str, list[int]]:
    folder.mkdir()
    (folder / "GTS800.cfg").write_text(cfg, encoding="utf-8")
    (folder / "machine.toml").write_text(
        f"[axis.3]\nposition = 0\nnegative_limit = {LIMIT}\npositive_limit = 80000\n",
        encoding="utf-8",
    )
    env = native_env(GTECAT_CARD="gts:4", GTECAT_MACHINE="machine.toml")
    env.pop("GTECAT_ENI")  # a card: no ENI anywhere
    r = subprocess.run(
        [str(exe), str(axis)], cwd=folder, capture_output=True, text=True, env=env, timeout=300
    )
    assert r.returncode == 0, (r.stdout, r.stderr)
    out = {}
    for line in r.stdout.splitlines():
        key, *values = line.split()
        out[key] = [int(float(v)) for v in values]
    return out


@pytest.mark.parametrize("wired", [True, False], ids=["axis 3 wired", "vendor file as is"])
@pytest.mark.long
def test_seed_002_limit_homing_runs_unchanged_on_gts4(seed_program, tmp_path, wired):
    out = run_seed(seed_program, tmp_path / "run", vendor_cfg(wired))
    assert out["init"] == [0] and out["home"] == [0] and out["close"] == [0]
    run, stage, error, capture, target = out["status"]
    assert (run, stage, error) == (0, 100, 0)  # HOME_STAGE_END, HOME_ERROR_NONE
    assert abs(capture - LIMIT) <= 20 / 2 + 1  # sampled limit: half a cycle at velLow 20
    assert target == capture + 10000  # homeOffset
    prf, enc, machine, sts = out["after"]
    assert (prf, enc) == (0, 0)  # the seed's GT_ZeroPos
    assert abs(machine - (LIMIT + 10000)) <= 11
    assert sts & (1 << 9) and not sts & 0x60  # servo on, no limit flag left


def test_seed_002_extraction_finds_the_whole_class():
    header, source = extract(seed_text())
    assert re.search(r"^enum Axis$", header, re.M) and header.rstrip().endswith("};")
    names = re.findall(r"^short Motion::(\w+)\(", source, re.M)
    assert names == ["init", "close", "axisStatus", "isMoving", "stop", "moveTo", "LimitHome",
                     "moveHomeInner"]  # fmt: skip
