"""The table property test through libgts (issue 13 quality bar): bad input from C - NULL
pointers, out-of-range values, an unknown core - gets the codes Python gives, for every
function of the table, in a child process (``fuzz_lib_worker.py`` says what is generated
and what each pair of calls must satisfy).  A crash or a hang fails the test with the
child's output, never the test run.  ``GTECAT_LONG=1`` fuzzes every function; the default run
a seeded sample (``GTECAT_SEED`` repeats one)."""

from __future__ import annotations

import os
import random
import subprocess
import sys

import pytest

from gtecat.gt import _core
from gtecat.native import protocol
from tests.conftest import LONG, campaign_seed

from .conftest import ROOT, needs_cc
from .fuzz_lib_worker import SKIP

pytestmark = needs_cc
EXAMPLES = 15  # per function: GT_x and its GTN_x twin (a random core) with the same arguments
TIMEOUT_S = 600
# child processes, each with every other function: the xdist workers share them (one for the
# default run's sample: a child's start-up costs more than its share of the sample)
BATCHES = 2 if LONG else 1
# The default run fuzzes a seeded sample of the functions (its cost must not grow with the
# table); GTECAT_LONG=1 every function with EXAMPLES each.
SAMPLE, SAMPLE_EXAMPLES = 40, 6
SEED = campaign_seed()


def _eligible() -> list[str]:
    return sorted(
        p.name
        for p in protocol.plans()
        if p.name not in SKIP and not p.unsupported and p.name in _core.REGISTRY
    )


def _fuzzed() -> list[str]:
    names = _eligible()
    if LONG:
        return names
    return sorted(random.Random(SEED).sample(names, min(SAMPLE, len(names))))


@pytest.mark.parametrize("batch", range(BATCHES))
def test_bad_input_through_the_library_gets_the_python_codes(libgts, batch):
    names = _fuzzed()[batch::BATCHES]
    examples = EXAMPLES if LONG else SAMPLE_EXAMPLES
    env = {k: v for k, v in os.environ.items() if not k.startswith("GTECAT_")}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    cmd = [sys.executable, "-m", "tests.gtecat.native.fuzz_lib_worker", "--examples"]
    try:
        r = subprocess.run(
            [*cmd, str(examples), *names],
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
    seed = "" if LONG else f"\n(sample seed {SEED}: GTECAT_SEED={SEED} repeats it)"
    assert r.returncode == 0, ("\n".join(failures)[-6000:] or out[-3000:]) + seed
    done = {ln.split()[1] for ln in out.splitlines() if ln.startswith("ok ")}
    assert done == set(names), sorted(set(names) - done)


def test_the_batches_cover_every_function_the_pair_can_run():
    names = _eligible()
    assert len(names) > 100
    batched = [n for b in range(BATCHES) for n in names[b::BATCHES]]
    assert sorted(batched) == names
