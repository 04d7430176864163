"""The table property test through libgts (issue 13 quality bar): bad input from C - NULL
pointers, out-of-range values, an unknown core - gets the codes Python gives, for every
function of the table, in a child process (``fuzz_lib_worker.py`` says what is generated
and what each pair of calls must satisfy).  A crash or a hang fails the test with the
child's output, never the test run."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from gtecat.gt import _core
from gtecat.native import protocol
from tests.conftest import is_setting

from .conftest import ROOT, needs_cc
from .fuzz_lib_worker import SKIP

pytestmark = needs_cc
# per function: GT_x and its GTN_x twin (a random core) with the same arguments; the default
# run calls every function with a few, GTECAT_LONG=N runs 15 x N (the suite's CPU budget)
_LONG = int(os.environ.get("GTECAT_LONG", "0") or 0)
EXAMPLES = 15 * _LONG if _LONG else 3
TIMEOUT_S = 600
BATCHES = 2  # child processes, each with every other function: the xdist workers share them


def _eligible() -> list[str]:
    return sorted(
        p.name
        for p in protocol.plans()
        if p.name not in SKIP and not p.unsupported and p.name in _core.REGISTRY
    )


@pytest.mark.parametrize("batch", range(BATCHES))
@pytest.mark.long
def test_bad_input_through_the_library_gets_the_python_codes(libgts, batch):
    names = _eligible()[batch::BATCHES]
    env = {k: v for k, v in os.environ.items() if not is_setting(k)}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    cmd = [sys.executable, "-m", "tests.gtecat.native.fuzz_lib_worker", "--examples"]
    try:
        r = subprocess.run(
            [*cmd, str(EXAMPLES), *(["--declared", "40"] if batch == 0 else []), *names],
            cwd=ROOT,
            env=env,
            capture_output=True,
            text=True,
            timeout=TIMEOUT_S,
        )
    except subprocess.TimeoutExpired as e:
        pytest.fail(f"the library fuzz still ran after {TIMEOUT_S} s:\n{(e.stdout or '')[-3000:]}")
    out = r.stdout + r.stderr
    if r.returncode < 0:
        pytest.fail(f"the library fuzz crashed (signal {-r.returncode}):\n{out[-3000:]}")
    failures = [ln for ln in out.splitlines() if ln.startswith("FAIL")]
    assert r.returncode == 0, "\n".join(failures)[-6000:] or out[-3000:]
    done = {ln.split()[1] for ln in out.splitlines() if ln.startswith("ok ")}
    declared = {ln.split()[1] for ln in out.splitlines() if ln.endswith("(declared)")}
    assert done - declared == set(names), sorted(set(names) - done)
    assert batch != 0 or len(declared) >= 30  # declared-only: 8 and one reason, C and Python


def test_the_batches_cover_every_function_the_pair_can_run():
    names = _eligible()
    assert len(names) > 100
    batched = [n for b in range(BATCHES) for n in names[b::BATCHES]]
    assert sorted(batched) == names
