"""Recordings and replays, application checks, the command line, the pytest plugin's options."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path
from types import SimpleNamespace

import pytest

from gtecat import gt
from gtecat.cli.main import main
from tests.conftest import EXAMPLES, is_setting

SCRIPT = textwrap.dedent(
    f"""
    from ctypes import byref, c_double, c_long, c_short, c_ubyte, c_uint32
    from gtecat import faults, gt

    gt.GT_Open(eni={str(EXAMPLES / "full_servo.eni")!r}, clock="auto", log="")
    gt.GT_InitEcatComm()
    st, clock = c_short(), c_long()
    while gt.GT_IsEcatReady(byref(st)) == 0 and st.value != 1:
        gt.GTE_Wait(1)
    gt.GT_StartEcatComm()
    raw = (c_ubyte * 2)(0x0F, 0)
    gt.GT_SetEcatRawData(0, 2, raw)
    gt.GTE_Wait(5)
    gt.GT_AxisOn(1)
    prm = gt.TTrapPrm()
    prm.acc = prm.dec = 0.5
    gt.GT_PrfTrap(1)
    gt.GT_SetTrapPrm(1, byref(prm))
    gt.GT_SetPos(1, 20000)
    gt.GT_SetVel(1, 10)
    gt.GT_Update(1)
    faults.inject("drive_fault", axis=1, code=0x2310, after_ms=200)
    sts = c_long()
    for _ in range(60):
        gt.GTE_Wait(10)
        gt.GT_GetSts(1, byref(sts))
    gt.GT_Update(1)
    data, size, ab = (c_ubyte * 4)(), c_uint32(), c_uint32()
    gt.GT_EcatSDOUpload(0, 0x603F, 0, data, 4, byref(size), byref(ab))
    enc = (c_double * 4)()
    gt.GT_GetEncPos(1, byref(enc, 16), 1, None)  # C: &enc[2]
    assert enc[2] != 0.0 and enc[0] == 0.0
    gt.GT_Close()
    """
)


@pytest.fixture(scope="module")
def recorded(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("rec")
    (folder / "app.py").write_text(SCRIPT)
    out = folder / "session.gtrec"
    assert main(["record", "-o", str(out), "--", "python3", str(folder / "app.py")]) == 0
    return out


def test_record_then_replay_matches(recorded: Path, capsys: pytest.CaptureFixture[str]) -> None:
    lines = recorded.read_text().splitlines()
    head = json.loads(lines[0])
    assert head["gtecat_recording"] == 1 and head["calls"] > 80
    entries = [json.loads(x) for x in lines[1:]]
    assert any(e.get("f") == "inject" and e["v"]["kind"] == "drive_fault" for e in entries)
    assert any("cp" in e for e in entries)
    sts = [e for e in entries if e.get("c") == "GT_GetSts"]
    assert any(int(e["o"]["1"]["ref"]["v"]) & 2 for e in sts if "o" in e)  # the alarm was seen
    # a pointer into an array (answered by the fast path): kept with its offset
    enc = [e for e in entries if e.get("c") == "GT_GetEncPos"]
    assert enc and enc[-1]["a"][1]["off"] == 16 and enc[-1]["r"] == 0
    assert main(["replay", str(recorded)]) == 0
    assert "calls match" in capsys.readouterr().out


def test_replay_reports_the_first_divergence(
    recorded: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    lines = recorded.read_text().splitlines()
    for i, line in enumerate(lines):
        e = json.loads(line)
        if e.get("c") == "GT_GetSts" and "o" in e:
            e["o"]["1"]["ref"]["v"] ^= 0x10
            lines[i] = json.dumps(e)
            break
    bad = tmp_path / "bad.gtrec"
    bad.write_text("\n".join(lines) + "\n")
    assert main(["replay", str(bad)]) == 1
    err = capsys.readouterr().err
    assert "GT_GetSts: argument 2 recorded" in err and "replay gives" in err
    assert main(["replay", str(recorded), "--eni", str(EXAMPLES / "manual_fig5_2.eni")]) == 1
    assert "diverged at call" in capsys.readouterr().err  # another bus: another session
    (tmp_path / "junk").write_text("hello\n")
    assert main(["replay", str(tmp_path / "junk")]) == 1
    assert "not a gtecat recording" in capsys.readouterr().err


def test_checks_name_the_script_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    app = tmp_path / "app.py"
    app.write_text(SCRIPT)
    assert main(["run", "--check", "--no-progress", str(app)]) == 3
    err = capsys.readouterr().err
    found = [x for x in err.splitlines() if x.startswith("check: ")]
    assert any(f"{app}:12:" in x and "skips a state" in x for x in found), err
    assert any(
        f"{app}:27:" in x and "GT_Update starts axis 1 while its alarm bit is set" in x
        for x in found
    ), err


def test_an_endless_ready_poll(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    app = tmp_path / "poll.py"
    app.write_text(
        "from ctypes import byref, c_short\n"
        "from gtecat import gt\n"
        f"gt.GT_Open(eni={str(EXAMPLES / 'full_servo.eni')!r}, log='')\n"
        "gt.GT_InitEcatComm()\n"
        "s = c_short()\n"
        "while gt.GT_IsEcatReady(byref(s)) == 0 and s.value != 1:\n"
        "    pass\n"
    )
    assert main(["run", "--check", "--no-progress", str(app)]) == 3
    err = capsys.readouterr().err
    assert f"check: {app}:6: GT_IsEcatReady answered not ready 200 times" in err, err


READY_LOOPS = f"""\
import time
from ctypes import byref, c_short, c_ulong
from gtecat import faults, gt
gt.GT_Open(eni={str(EXAMPLES / "full_servo.eni")!r}, log="")
gt.GT_InitEcatComm()
s, c = c_short(), c_ulong()
gt.GT_GetClock(byref(c))
t0 = c.value
while True:  # the manual's wait, with a limit on the controller's clock
    gt.GT_IsEcatReady(byref(s))
    gt.GT_GetClock(byref(c))
    if s.value == 1 or c.value - t0 > 5000:
        break
gt.GT_StartEcatComm()
deadline = time.monotonic() + 60
for _ in range(250):  # a health check of a bus that is up: not a wait
    gt.GT_IsEcatReady(byref(s))
    if s.value != 1 or time.monotonic() > deadline:
        break
    gt.GTE_Wait(1)
faults.inject("link_down", after_slave=-1)  # the bus goes and stays away
gt.GTE_Wait(1)
for _ in range(210):  # a wait with a limit on the program's own clock
    gt.GT_IsEcatReady(byref(s))
    if s.value == 1 or time.monotonic() > deadline:
        break
for _ in range(210):  # a wait that only pauses: nothing would end it but the bus
    gt.GT_IsEcatReady(byref(s))
    if s.value == 1:
        break
    gt.GTE_Wait(1)
"""


def test_ready_poll_counts_only_waits_without_a_clock(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    app = tmp_path / "loops.py"
    app.write_text(READY_LOOPS)
    assert main(["run", "--check", "--no-progress", str(app)]) == 3
    err = capsys.readouterr().err
    found = [x for x in err.splitlines() if x.startswith("check: ")]
    assert found[0].startswith(f"check: {app}:28: GT_IsEcatReady answered not ready"), err
    assert len(found) == 2 and found[1] == "check: 1 finding", err


def test_fault_kinds_and_refusals(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["fault", "kinds", "--json"]) == 0
    kinds = {r["kind"] for r in json.loads(capsys.readouterr().out)}
    assert {"drive_fault", "link_down", "drop_responses", "mailbox_abort", "switch_stuck"} <= kinds
    assert main(["fault", "inject", "melt_down"]) == 1
    assert "unknown fault kind" in capsys.readouterr().err
    assert main(["fault", "inject", "drive_fault", "axis"]) == 1
    assert "KEY=VALUE" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("values", "said"),
    [
        (["axis=1", "axis=2"], "axis= is given twice (axis=1 and axis=2): give it once"),
        (["axis=1", "name="], "'name=': name has no value"),
        (["axis=", "code=0x2310"], "'axis=': axis has no value"),
    ],
)
def test_fault_inject_refuses_a_key_twice_or_empty(
    values: list[str], said: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["fault", "inject", "drive_fault", *values]) == 1  # refused before connecting
    err = capsys.readouterr().err
    assert said in err and "no running gtecat" not in err, err


def test_an_empty_fault_name_is_refused() -> None:
    from gtecat import faults

    with pytest.raises(faults.FaultSpecError, match="name must be text that names the fault"):
        faults.spec_from_dict({"kind": "drive_fault", "axis": 1, "name": "  "})
    assert faults.spec_from_dict({"kind": "drive_fault", "axis": 1, "name": "cut"}).name == "cut"


PLUGIN_TESTS = textwrap.dedent(
    """
    from ctypes import byref, c_long

    def test_a_drive_fault(gtecat_bus, gtecat_faults):
        gtecat_bus.axis_on(1)
        gtecat_faults.inject("drive_fault", axis=1, code=0x2310, after_cycles=5)
        gtecat_bus.wait(20)
        sts = c_long()
        gtecat_bus.gt.GT_GetSts(1, byref(sts))
        assert sts.value & 2
        assert gtecat_faults.listing()[0]["state"] == "active"

    def test_fails_and_keeps_its_recording(gtecat_bus):
        gtecat_bus.gt.GT_SetEcatRawData(0, 2, (__import__("ctypes").c_ubyte * 2)(0x0F, 0))
        gtecat_bus.wait(3)
        assert False, "on purpose"
    """
)


@pytest.mark.long("a pytest run in a child process")
def test_plugin_fixture_record_and_check(tmp_path: Path) -> None:
    (tmp_path / "test_m.py").write_text(PLUGIN_TESTS)
    (tmp_path / "pytest.ini").write_text("[pytest]\ngtecat_eni = full_servo\n")
    env = {k: v for k, v in os.environ.items() if not is_setting(k)}
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q", "-n", "0",
         "--gtecat-record", "--gtecat-check", "--gtecat-trace-dir", "traces", "-s"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    out = done.stdout + done.stderr
    assert "1 passed" in out and "1 failed" in out, out
    assert "gtecat replay " in out and "gtecat-recording.jsonl" in out
    kept = tmp_path / "traces" / "test_m.py_test_fails_and_keeps_its_recording.gtrec.jsonl"
    assert kept.is_file()
    from gtecat.cli.main import main as gtecat_main

    assert gtecat_main(["replay", str(kept)]) == 0  # the failing test's session, again
    assert "check: " in out and "test_m.py:14: axis 1: controlword 0x000F" in out, out


def test_checks_of_what_the_drive_sees(tmp_path: Path) -> None:
    """A CSP step past the following-error window, a mode change in motion, an enable in
    FAULT without a fault reset: each found once, at the line of the call that did it."""
    import io
    from ctypes import byref, c_short, c_ubyte

    from gtecat import faults
    from gtecat.faults.checks import Checker

    m = tmp_path / "m.toml"
    m.write_text("[axis.1]\nfollowing_error_window = 100\n")
    out = io.StringIO()
    checker = Checker(out).start()
    try:
        gt.GT_Open(eni=str(EXAMPLES / "full_servo.eni"), machine=str(m), clock="lockstep", log="")
        gt.GT_InitEcatComm()
        st = c_short()
        while gt.GT_IsEcatReady(byref(st)) == 0 and st.value != 1:
            gt.GTE_Wait(1)
        gt.GT_StartEcatComm()
        gt.GT_AxisOn(1)
        gt.GTE_Wait(10)
        prm = gt.TTrapPrm()
        prm.acc = prm.dec = 50
        gt.GT_PrfTrap(1)
        gt.GT_SetTrapPrm(1, byref(prm))
        gt.GT_SetPos(1, 100000)
        gt.GT_SetVel(1, 300)
        gt.GT_Update(1)  # a step of 300 counts a cycle: the window is 100
        gt.GTE_Wait(20)
        gt.GT_SetEcatAxisMode(1, 9)  # in motion
        gt.GTE_Wait(20)
        faults.inject("drive_fault", axis=1, code=0x2310)
        gt.GTE_Wait(20)
        gt.GT_SetEcatRawData(0, 2, (c_ubyte * 2)(0x0F, 0))  # enable, no fault reset
        gt.GTE_Wait(3)
    finally:
        checker.stop()
    rules = [f.rule for f in checker.findings]
    assert rules == ["csp-step", "mode-while-moving", "enable-in-fault"], out.getvalue()
    here = Path(__file__).name
    assert all(Path(f.file).name == here for f in checker.findings)
    assert out.getvalue().count("check: ") == 3


def test_recorded_values_come_back_as_they_were() -> None:
    import ctypes
    import json

    from gtecat import gt
    from gtecat.faults.record import decode, encode

    prm = gt.TTrapPrm()
    prm.acc, prm.dec = float("inf"), 0.5
    values = [
        ctypes.byref(ctypes.c_double(float("nan"))),
        ctypes.byref(prm),
        (ctypes.c_long * 3)(1, 2, 3),
        ctypes.create_string_buffer(b"abc", 8),
        [ctypes.c_short(4)],
        bytearray(b"xy"),
        float("-inf"),
        3,
        None,
        ctypes.byref((ctypes.c_double * 4)(1, 2, 3, 4), 16),  # C: &arr[2]
        ctypes.byref(ctypes.c_long(7), 0),
    ]
    for x in values:
        text = json.dumps(encode(x), allow_nan=False)
        assert json.dumps(encode(decode(json.loads(text))), allow_nan=False) == text
    # the offset comes back: the same address into the same kind of object
    from gtecat.gt.args import byref_address

    again = decode(json.loads(json.dumps(encode(values[-2]))))
    assert byref_address(again) - ctypes.addressof(again._obj) == 16


C_PROGRAM = r"""
#include <stdio.h>
#include "gts.h"
int main(void) {
    short st = 0; long sts = 0; int i;
    GT_Open(0, 1);
    GT_InitEcatComm();
    for (i = 0; i < 5000 && !(GT_IsEcatReady(&st) == 0 && st == 1); i++) GTE_Wait(1);
    GT_StartEcatComm();
    GT_AxisOn(1);
    GTE_Wait(20);
    GT_GetSts(1, &sts, 1, NULL);
    printf("sts %ld\n", sts);
    GT_Close();
    return 0;
}
"""


@pytest.mark.long("builds and runs a C program")
def test_a_c_program_is_recorded_and_replayed(tmp_path: Path) -> None:
    import shutil

    if shutil.which("gcc") is None:
        pytest.skip("no C compiler (gcc) on PATH")
    src = tmp_path / "prog.c"
    src.write_text(C_PROGRAM)
    flags = subprocess.run(
        [sys.executable, "-m", "gtecat", "lib", "--cflags", "--libs"],
        capture_output=True, text=True, check=True,
    ).stdout.split()  # fmt: skip
    subprocess.run(["gcc", str(src), "-o", str(tmp_path / "prog"), *flags], check=True)
    shutil.copy(EXAMPLES / "full_servo.eni", tmp_path / "Gecat.eni")
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}:{os.environ['PATH']}")
    env.pop("GTECAT_CONTROLLER", None)
    out = tmp_path / "c.gtrec"
    done = subprocess.run(
        [sys.executable, "-m", "gtecat", "record", "-o", str(out), "--", "./prog"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert "sts 512" in done.stdout, done.stdout + done.stderr
    # (7 calls when the bus is ready at the first look; the library's controller follows the
    # wall clock between its client's calls, so a slow start - a first build of the library -
    # adds GT_IsEcatReady and GTE_Wait pairs, each recorded and replayed)
    calls = re.search(r"record: (\d+) GT calls", done.stderr)
    assert calls is not None, done.stderr
    assert int(calls[1]) >= 7 and (int(calls[1]) - 7) % 2 == 0, done.stderr
    assert main(["replay", str(out)]) == 0


def test_plugin_findings_are_warnings_at_the_application_line() -> None:
    """``--gtecat-check`` in pytest: each finding a warning at the application's file and line
    (pytest's warnings summary shows it, from xdist workers too), not text on the test's
    captured stderr."""
    from gtecat.faults.checks import Finding, GtecatCheckWarning
    from gtecat.pytest_plugin import _warn_findings

    found = [Finding("move-with-alarm", "/app/cell.py", 42, "axis 3: GT_Update with its alarm set")]
    with pytest.warns(GtecatCheckWarning) as seen:
        _warn_findings(found)
    (w,) = seen.list
    assert (w.filename, w.lineno) == ("/app/cell.py", 42)
    assert str(w.message).startswith("check: /app/cell.py:42: axis 3: GT_Update")


def test_plugin_findings_fail_the_test_itself_when_warnings_are_errors() -> None:
    """``-W error::...GtecatCheckWarning``: the findings of the test's call are warned as the
    call ends, inside it, so pytest reports the test FAILED (not an ERROR of its teardown);
    the ones warned there are not warned again at the teardown."""
    import warnings

    from gtecat import pytest_plugin as plugin
    from gtecat.faults.checks import Finding, GtecatCheckWarning

    class Outcome:
        excinfo = None
        forced: BaseException | None = None

        def force_exception(self, e: BaseException) -> None:
            self.forced = e

    found = [Finding("cw-skip", "/app/t.py", n, f"axis {n}: skips") for n in (3, 4)]
    item = SimpleNamespace(stash={plugin.CHECK_KEY: [SimpleNamespace(findings=found), 0]})
    with warnings.catch_warnings():
        warnings.simplefilter("error", GtecatCheckWarning)
        hook = plugin.pytest_runtest_call(item)
        next(hook)
        outcome = Outcome()
        with pytest.raises(StopIteration):
            hook.send(outcome)
    assert isinstance(outcome.forced, GtecatCheckWarning)
    assert str(outcome.forced).splitlines() == [
        "check: /app/t.py:3: axis 3: skips [CiA 402 state machine]",
        "check: /app/t.py:4: axis 4: skips [CiA 402 state machine]",
    ]
    assert item.stash[plugin.CHECK_KEY][1] == 2  # the teardown warns from the third on
