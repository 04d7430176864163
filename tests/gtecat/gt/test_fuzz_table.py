"""The function table fuzzed: every GT function with good and bad arguments.

Every ``GT_*`` function, its ``GTN_*`` twin and every ``GTE_*`` helper is called by a
hypothesis test with arguments generated from the table's parameter types, and a seeded
sample of the declared-only functions (every one with ``GTECAT_LONG=1``) with anything at
all: they must answer 8 (``fuzz_table_worker.py`` says what is generated and what each
call must satisfy). A bad pointer could crash the interpreter, so the fuzzing runs in
child processes: one for every batch in the default run, one per batch under
``GTECAT_LONG=1`` (all started at once in a plain run, one per test under pytest-xdist).
The functions that take the bus down (GT_Close, GT_TerminateEcatComm, GTE_UnplugSlave, ...)
have their own batch, each restored after each call. ``CI`` in the environment
derandomises the children, as tests/conftest.py does here.

Below them, the cases outside checkers found, as plain regression tests.
"""

from __future__ import annotations

import math
import os
import random
import subprocess
import sys
import time
from ctypes import (
    POINTER,
    addressof,
    byref,
    c_double,
    c_long,
    c_short,
    c_ubyte,
    c_ulong,
    create_string_buffer,
    pointer,
)

import numpy as np
import pytest

from gtecat import gt
from gtecat.gt._core import REGISTRY
from gtecat.gt.surface import entries
from gtecat.gt.table import FUNCTIONS
from tests.conftest import ROOT, campaign_seed
from tests.gtecat.gt.conftest import bring_up

# --- the fuzzer, in child processes --------------------------------------------------------------
STATE_CHANGING = {
    "Open",
    "OpenCard",
    "NetInit",
    "Close",
    "Reset",
    "InitEcatComm",
    "StartEcatComm",
    "TerminateEcatComm",
    "LoadConfig",
    "UnplugSlave",
    "ReplugSlave",
    "SetCardNo",  # every later call addresses another card
    "SetCore",  # every later GT_ call addresses another core
}
# The default run calls every function with a few examples (the suite's CPU budget);
# GTECAT_LONG=N runs the campaign: 15 x N examples per function, 8 x N per twin (fresh seeds
# unless CI is set)
LONG = int(os.environ.get("GTECAT_LONG", "0") or 0)
EXAMPLES = 15 * LONG if LONG else 1  # per GT_/GTE_ function
TWIN_EXAMPLES = 8 * LONG if LONG else 1  # per GTN_ twin: the same code, mostly the core is new
BATCH_TIMEOUT_S = 900 * LONG if LONG else 150  # a backstop: each call has its own 10 s alarm
# GTECAT_LONG: one child per xdist worker; the default run's sample fits one (a child costs
# about 1 s of CPU before its first call)
CALL_BATCHES = 2 if LONG else 1


#: declared-only functions fuzzed in a plain run (a seeded sample); GTECAT_LONG=1: every one
DECLARED_SAMPLE = 40


def _declared() -> list[str]:
    """Declared-only names (gtecat.gt.declared) for the fuzzer: they must answer 8 whatever
    they are given."""
    names = sorted(e.name for e in entries() if not e.emulated)
    if os.environ.get("GTECAT_LONG"):
        return names
    return sorted(random.Random(25).sample(names, min(DECLARED_SAMPLE, len(names))))


#: emulated functions fuzzed in a plain run: a sample chosen by the campaign seed (the same on
#: every CI run, another on each developer's run); GTECAT_LONG=1: every one
EMULATED_SAMPLE = 100


def _batches() -> dict[str, list[str]]:
    names = sorted(REGISTRY)
    if not LONG:
        names = sorted(random.Random(campaign_seed()).sample(names, EMULATED_SAMPLE))
    state = [n for n in names if n.partition("_")[2] in STATE_CHANGING]
    rest = [n for n in names if n not in state]
    calls = {f"calls-{'abcdefgh'[i]}": rest[i::CALL_BATCHES] for i in range(CALL_BATCHES)}
    # the declared-only sample rides in the state-changing child (one interpreter start less)
    return {**calls, "state-changing+declared": state + _declared()}


BATCHES = _batches()
_RUNS: dict[str, subprocess.Popen[str]] = {}
#: a child's exit code and output, read once (the default run's one child serves every batch)
_DONE: dict[int, tuple[int, str]] = {}


def _start(batch: str) -> subprocess.Popen[str]:
    """The child that fuzzes ``batch``.  The default run fuzzes every batch in one child,
    one after the other (each function is restored after its calls whatever the batch; a
    child costs about half a second of CPU before its first call), and each batch's test
    reads its own functions' lines; GTECAT_LONG=1 runs a child per batch.  A batch whose
    child runs already is given that child (no second one: it would run unread)."""
    if batch not in _RUNS:
        names = BATCHES[batch] if LONG else [n for names in BATCHES.values() for n in names]
        proc = _start_names(names)
        for b in [batch] if LONG else BATCHES:
            _RUNS.setdefault(b, proc)
    return _RUNS[batch]


def _start_names(names: list[str]) -> subprocess.Popen[str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")])
    # the child draws from its own strategies only: no other package's hypothesis plugin
    # (trio's imports trio and pytest, a tenth of the child's start)
    env.setdefault("HYPOTHESIS_NO_PLUGINS", "1")
    cmd = [
        sys.executable,
        "-m",
        "tests.gtecat.gt.fuzz_table_worker",
        "--examples",
        str(EXAMPLES),
        "--twin-examples",
        str(TWIN_EXAMPLES),
        *names,
    ]
    return subprocess.Popen(
        cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    )


@pytest.fixture(scope="module")
def fuzz_runs():
    """The batches' child processes, killed if still running at the end.  In a plain run all
    batches start at once (they run in parallel); under pytest-xdist each test starts its own
    batch, so the workers share them out instead of every worker running all of them."""
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        for batch in BATCHES:
            _start(batch)
    yield _RUNS
    for p in _RUNS.values():
        if p.poll() is None:
            p.kill()
            p.wait()
    _RUNS.clear()
    _DONE.clear()


def test_the_batches_cover_every_function_gt_exposes():
    # every registered function comes from the table with its twin (table lines not
    # implemented yet are the table tests' business, not the fuzzer's)
    for name in REGISTRY:
        base = "GT_" + name[4:] if name.startswith("GTN_") else name
        assert base in FUNCTIONS or name in FUNCTIONS, name  # or a GTN_x line of its own
        if name.startswith("GT_") and FUNCTIONS[name].gtn:  # GT_SetCore(core) has none
            assert "GTN_" + name[3:] in REGISTRY, name
    covered = [n for names in BATCHES.values() for n in names if n in REGISTRY]
    if LONG:
        assert sorted(covered) == sorted(REGISTRY)
    else:  # the plain run's sample: distinct registered names, none twice
        assert len(covered) == len(set(covered)) == EMULATED_SAMPLE
        assert set(covered) <= set(REGISTRY)
    declared = _declared()
    assert declared and not set(declared) & set(REGISTRY)
    assert set(declared) <= set(BATCHES["state-changing+declared"])


@pytest.mark.parametrize("batch", list(BATCHES))
def test_fuzz_every_function_with_good_and_bad_arguments(fuzz_runs, batch):
    proc = fuzz_runs.get(batch) or _start(batch)
    if id(proc) not in _DONE:
        try:
            out, _ = proc.communicate(timeout=BATCH_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            proc.kill()
            out, _ = proc.communicate()
            pytest.fail(f"batch {batch} still running after {BATCH_TIMEOUT_S} s:\n{out[-3000:]}")
        _DONE[id(proc)] = proc.returncode, out
    rc, out = _DONE[id(proc)]
    if rc < 0:
        pytest.fail(f"batch {batch} crashed (signal {-rc}):\n{out[-3000:]}")
    failures = [ln for ln in out.splitlines() if not ln.startswith(("ok ", "WARN "))]
    ours = set(BATCHES[batch])
    failed = {ln.split()[1].rstrip(":") for ln in out.splitlines() if ln.startswith("FAIL ")}
    assert not failed & ours and (rc == 0 or failed), "\n".join(failures)[-6000:]
    done = {ln.split()[1] for ln in out.splitlines() if ln.startswith("ok ")}
    assert done >= ours, sorted(ours - done)
    assert "WARN" not in out, [ln for ln in out.splitlines() if ln.startswith("WARN")]


# --- regressions ---------------------------------------------------------------------------------
@pytest.fixture
def bus():
    bring_up(clock="lockstep")


def _answers() -> bool:
    raw = (c_ubyte * 4)()
    return gt.GT_GetSts(1, byref(c_long())) == 0 and gt.GT_GetEcatRawData(0, 4, raw) == 0


def test_get_version_refuses_a_null_and_a_one_byte_pointer_and_writes_nothing(bus):
    assert gt.GT_GetVersion(POINTER(c_ubyte)()) == 7
    assert gt.GT_GetVersion(None) == 7
    buf = (c_ubyte * 80)(*[0xA5] * 80)  # a canary all round the one byte
    one = c_ubyte.from_buffer(buf, 8)
    assert gt.GT_GetVersion(pointer(one)) == 7
    assert gt.GT_GetVersion(byref(one)) == 7
    assert bytes(buf) == b"\xa5" * 80
    assert _answers()


def test_get_version_into_an_offset_buffer_writes_only_its_text(bus):
    buf = (c_ubyte * 80)(*[0xA5] * 80)
    assert gt.GT_GetVersion(byref(buf, 8)) == 0
    data = bytes(buf)
    text, _, rest = data[8:].partition(b"\0")
    assert data[:8] == b"\xa5" * 8 and text.startswith(b"010 ")
    assert rest == b"\xa5" * len(rest)  # nothing after the NUL
    s = create_string_buffer(64)
    assert gt.GT_GetVersion(s) == 0 and s.value == text


def test_get_sts_with_count_and_a_zero_clock_as_manual_examples_3_1_and_8_1(bus):
    sts = c_long()
    assert gt.GT_GetSts(1, byref(sts), 1, 0) == 0
    assert gt.GTN_GetSts(1, 1, byref(sts), 1, 0) == 0
    sts2 = (c_long * 2)()
    clock = c_ulong()
    assert gt.GT_GetSts(1, sts2, 2, byref(clock)) == 0


def test_a_typed_null_is_a_null_for_an_optional_pointer_and_refused_for_a_required_one(bus):
    sts = c_long()
    assert gt.GT_GetSts(1, byref(sts), 1, POINTER(c_ulong)()) == 0
    assert gt.GT_GetClock(byref(c_ulong()), POINTER(c_ulong)()) == 0
    assert gt.GT_GetEcatSlaves(byref(c_short()), POINTER(c_short)()) == 0
    assert gt.GT_GetSts(1, POINTER(c_long)()) == 7


@pytest.mark.parametrize(
    "call",
    [
        lambda sts: gt.GTN_GetSts(),
        lambda sts: gt.GTN_GetSts(axis=1, pSts=byref(sts)),  # no core at all
        lambda sts: gt.GTN_GetSts("1", 1, byref(sts)),
        lambda sts: gt.GTN_GetSts(1.0, 1, byref(sts)),
        lambda sts: gt.GTN_GetSts(None, 1, byref(sts)),
        lambda sts: gt.GTN_GetSts(math.nan, 1, byref(sts)),
        lambda sts: gt.GTN_GetSts(3, 1, byref(sts)),  # core 2 is the card's second core
        lambda sts: gt.GTN_GetSts(1 << 40, 1, byref(sts)),
        lambda sts: gt.GTN_Close(2),
        lambda sts: gt.GTN_Open(0, 0, 1),  # the core-first form of earlier releases
        lambda sts: gt.GTN_Close("1"),
    ],
)
def test_gtn_with_a_missing_or_bad_core_is_7_and_the_bus_stays_up(bus, call):
    sts = c_long(-12345)
    assert call(sts) == 7, gt.GTE_GetLastError()
    assert sts.value == -12345
    assert _answers()
    assert gt.GTN_GetSts(1, 1, byref(sts)) == 0
    assert gt.GTN_GetSts(core=1, axis=1, pSts=byref(sts)) == 0


def test_gte_helpers_have_no_gtn_twin():
    gte = [n for n in FUNCTIONS if n.startswith("GTE_")]
    assert gte
    for n in gte:
        assert not hasattr(gt, "GTN__" + n[4:]), n  # GTN__Wait, GTN__UnplugSlave
        assert not hasattr(gt, "GTN_" + n[4:]), n
    assert not hasattr(gt, "GTN__Wait") and not hasattr(gt, "GTN__UnplugSlave")


@pytest.mark.parametrize("ms", [2**64, -(2**64), 86_400_001, -1, math.nan, math.inf, "1", None])
def test_gte_wait_out_of_range_is_7_at_once(bus, ms):
    clock = c_ulong()
    assert gt.GT_GetClock(byref(clock)) == 0
    before = clock.value
    t0 = time.monotonic()
    assert gt.GTE_Wait(ms) == 7
    assert time.monotonic() - t0 < 30  # refused at once: a wait of a day would never end
    assert gt.GT_GetClock(byref(clock)) == 0 and clock.value == before


def test_a_raw_address_is_7_and_never_dereferenced(bus):
    sts = c_long(-12345)
    assert gt.GT_GetSts(1, addressof(sts)) == 7
    assert sts.value == -12345
    raw = (c_ubyte * 4)(1, 2, 3, 4)
    assert gt.GT_GetEcatRawData(0, 4, addressof(raw)) == 7
    assert bytes(raw) == b"\x01\x02\x03\x04"


def test_read_only_buffers_for_out_pointers_are_7(bus):
    assert gt.GT_GetEcatRawData(0, 4, b"\0\0\0\0") == 7
    assert gt.GT_GetVersion(bytes(64)) == 7
    frozen = np.zeros(2, dtype=np.int32)
    frozen.flags.writeable = False
    assert gt.GT_GetSts(1, frozen) == 7
    assert gt.GT_GetEcatRawData(0, 4, memoryview(bytes(4))) == 7
    assert gt.GT_SetEcatRawData(0, 2, bytes(2)) == 0  # an input buffer may be read-only
    assert _answers()


def test_a_structure_for_a_numeric_pointer_is_7(bus):
    assert gt.GT_GetClock(byref(gt.TTrapPrm())) == 7
    assert gt.GT_GetEcatSlaves(byref(c_short()), byref(gt.TJogPrm())) == 7
    assert gt.GT_GetPrfPos(1, byref(c_double())) == 0
    assert _answers()


def test_a_keyword_given_twice_to_a_fast_path_function_is_7_not_a_typeerror(bus):
    """The fast path's wrappers (raw image, IO pair, status readers) once bound their own
    parameter names: ``offset=`` beside a positional offset raised a TypeError."""
    buf = (c_ubyte * 16)()
    sts = c_long()
    assert gt.GT_SetEcatRawData(0, 4, buf, offset=0) == 7
    assert "offset" in gt.GTE_GetLastError()
    assert gt.GT_GetEcatRawData(0, 4, buf, size=4) == 7
    assert gt.GT_EcatIOReadInput(2, 0, 1, buf, slave=2) == 7
    assert gt.GT_GetSts(1, byref(sts), 1, count=1) == 7
    assert gt.GT_GetSts(1, byref(sts), count=1) == 0  # once, as a keyword: fine
    assert _answers()
