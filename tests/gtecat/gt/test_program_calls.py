"""Chapter 10, 11.8 and 12 through the GT API: compile, download, threads, MRAM, MAC address.

Lockstep clock throughout (time passes only through GTE_Wait), except where the
auto mode is the point; the MRAM store of every test is a file in its tmp_path.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from ctypes import (
    byref,
    c_double,
    c_int16,
    c_long,
    c_short,
    c_ubyte,
    c_ulong,
    create_string_buffer,
)
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.cli.main import main as cli
from tests.conftest import EXAMPLES, ROOT
from tests.gtecat.gt.conftest import bring_up

SUM = (EXAMPLES / "example_10_1_sum.c").read_text(encoding="utf-8")


@pytest.fixture(autouse=True)
def _mram_in_tmp(tmp_path, monkeypatch):
    monkeypatch.setenv("GTECAT_MRAM", str(tmp_path / "Gecat.mram"))
    monkeypatch.delenv("GTECAT_PROGRAM_SPEED", raising=False)


def open_bare(clock: str = "lockstep", **options) -> None:
    options.setdefault("log", "")
    assert gt.GT_Open(clock=clock, **options) == 0, gt.GTE_GetLastError()


def compile_text(tmp_path: Path, text: str, name: str = "prog.c") -> Path:
    src = tmp_path / name
    src.write_text(text, encoding="utf-8")
    info = gt.TCompileInfo()
    rc = gt.GT_Compile(str(src), byref(info))
    assert rc == 0, gt.GTE_GetLastError()
    return src.with_suffix(".bin")


def load(tmp_path: Path, text: str) -> None:
    assert gt.GT_Download(str(compile_text(tmp_path, text))) == 0, gt.GTE_GetLastError()


def fun_id(name: str) -> int:
    f = c_short()
    assert gt.GT_GetFunId(name, byref(f)) == 0, gt.GTE_GetLastError()
    return f.value


def var(function, name: str) -> gt.TVarInfo:
    info = gt.TVarInfo()
    assert gt.GT_GetVarId(function, name, byref(info)) == 0, gt.GTE_GetLastError()
    return info


def set_value(page: int, info, *values: float) -> None:
    arr = (c_double * len(values))(*values)
    assert gt.GT_SetVarValue(page, byref(info), arr, len(values)) == 0, gt.GTE_GetLastError()


def get_value(page: int, info, count: int = 1) -> list[float]:
    arr = (c_double * count)()
    assert gt.GT_GetVarValue(page, byref(info), arr, count) == 0, gt.GTE_GetLastError()
    return list(arr)


def status(thread: int) -> gt.TThreadSts:
    s = gt.TThreadSts()
    assert gt.GT_GetThreadSts(thread, byref(s)) == 0
    return s


def clock_ms() -> int:
    c = c_ulong()
    gt.GT_GetClock(byref(c))
    return c.value


def wait_idle(threads, limit_ms: int = 5000) -> int:
    t0 = clock_ms()
    while any(status(t).run for t in threads):
        assert clock_ms() - t0 < limit_ms, "threads still running"
        gt.GTE_Wait(1)
    return clock_ms() - t0


def thread_error(thread: int) -> str:
    buf = create_string_buffer(256)
    gt.GTE_GetThreadError(thread, buf)
    return buf.value.decode()


# --- examples 10-1 and 10-2 ------------------------------------------------------------------
def test_example_10_1_as_printed(tmp_path, monkeypatch):
    open_bare()
    monkeypatch.chdir(tmp_path)
    compile_text(tmp_path, SUM, "sum.c")
    assert gt.GT_Download("sum.bin") == 0
    f = c_short()
    assert gt.GT_GetFunId("add", byref(f)) == 0 and f.value == 0
    s, b, e = var(0, "sum"), var(b"add", "begin"), var("add", "end")
    assert (s.id, s.dataType, s.name) == (0, 0, b"sum")
    assert gt.GT_Bind(0, f.value, 0) == 0
    set_value(-1, s, 0)
    set_value(0, b, 1)
    set_value(0, e, 100)
    assert gt.GT_RunThread(0) == 0
    assert status(0).run == 1
    # 504 instructions at 100 per controller millisecond: running after 5 ms, done in the 6th
    gt.GTE_Wait(5)
    assert status(0).run == 1
    gt.GTE_Wait(1)
    st = status(0)
    assert (st.run, st.error, st.result, st.line) == (0, 0, 5050.0, 21)
    assert get_value(-1, s) == [5050.0]


def test_example_10_2_two_threads_one_function_two_pages(tmp_path):
    open_bare()
    load(tmp_path, SUM)
    fid = fun_id("add")
    s, b, e = var(None, "sum"), var("add", "begin"), var("add", "end")
    assert gt.GT_Bind(0, fid, 0) == 0 and gt.GT_Bind(1, fid, 1) == 0
    set_value(-1, s, 0)
    set_value(0, b, 1)
    set_value(0, e, 50)
    set_value(1, b, 51)
    set_value(1, e, 100)
    assert gt.GT_RunThread(0) == 0 and gt.GT_RunThread(1) == 0
    took = wait_idle((0, 1))
    assert get_value(-1, s) == [5050.0]
    assert get_value(0, b) == [1.0] and get_value(1, b) == [51.0]  # each page its own locals
    assert 5 <= took <= 6  # 2 x 254 instructions share 100 per ms
    assert {status(0).error, status(1).error} == {0}


@pytest.mark.parametrize(
    "name", ["example_10_1_sum", "example_10_2_two_threads", "example_11_3_mram_write"]
)
def test_example_scripts_succeed(name, tmp_path, capsys):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod  # dataclasses look their module up
    try:
        spec.loader.exec_module(mod)
    finally:
        sys.modules.pop(name, None)
    argv = ["--keep", str(tmp_path)] if name.startswith("example_10") else []
    assert mod.main(argv) == 0, capsys.readouterr().out
    if name.startswith("example_10"):
        assert "sum = 5050" in capsys.readouterr().out
        assert (tmp_path / "sum.bin").is_file() and (tmp_path / "sum.ini").is_file()


@pytest.mark.long
def test_examples_11_3_and_11_4_in_two_fresh_processes(tmp_path):
    store = tmp_path / "store.mram"
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    env.pop("GTECAT_MRAM", None)

    def script(name, *args):
        return subprocess.run(
            [sys.executable, str(EXAMPLES / name), "--mram", str(store), *args],
            env=env,
            capture_output=True,
            text=True,
            timeout=120,
            cwd=tmp_path,
        )

    r = script("example_11_4_mram_read.py")
    assert r.returncode == 0 and "[0]" in r.stdout, r.stdout + r.stderr  # never written: zeros
    r = script("example_11_3_mram_write.py")
    assert r.returncode == 0, r.stdout + r.stderr
    r = script("example_11_4_mram_read.py")
    assert r.returncode == 0 and "[12345]" in r.stdout, r.stdout + r.stderr
    assert not (tmp_path / "Gecat.mram").exists()


# --- timing ----------------------------------------------------------------------------------
BUSY = """\
int n;
int f()
{
    int i;
    int cc;
    i = 0;
top:
    i = i + 1;
    cc = i < n;
    if(cc) goto top;
    return i;
}
"""


@pytest.mark.parametrize(("n", "speed", "ms"), [(1000, None, 31), (1000, 1000.0, 4), (10, 1.0, 32)])
def test_a_busy_loop_is_timed_in_controller_milliseconds(tmp_path, n, speed, ms):
    open_bare()
    load(tmp_path, BUSY)
    if speed is not None:
        assert gt.GTE_SetProgramSpeed(speed) == 0
    set_value(-1, var(None, "n"), n)
    assert gt.GT_Bind(0, fun_id("f"), 0) == 0
    assert gt.GT_RunThread(0) == 0
    # 1 + 3n + 1 instructions; the thread ends in cycle ceil(that / speed)
    gt.GTE_Wait(ms - 1)
    assert status(0).run == 1
    gt.GTE_Wait(1)
    assert (status(0).run, status(0).result) == (0, n)


def test_auto_clock_programs_run_while_the_host_polls(tmp_path):
    open_bare("auto")
    load(tmp_path, BUSY)
    set_value(-1, var(None, "n"), 1000)
    gt.GT_Bind(0, fun_id("f"), 0)
    t0 = clock_ms()
    gt.GT_RunThread(0)
    polls = 0
    while status(0).run:  # each call costs 50 µs of controller time
        polls += 1
    assert status(0).result == 1000
    assert 29 <= clock_ms() - t0 <= 32
    assert polls > 500


# --- fixed point, arrays, variables ----------------------------------------------------------
FIXED = """\
double d;
double e;
int same;
double arr[8];
int idx[3];
double total;
int f()
{
    int i;
    int cc;
    d = 0.1 * 3.0;
    e = 0.3;
    same = d == e;
    i = 0;
    total = 0;
top:
    total = total + arr[i];
    i = i + 1;
    cc = i < 8;
    if(cc) goto top;
    idx[2] = i;
    return 0;
}
"""


def test_fixed_point_values_read_back_exactly(tmp_path):
    open_bare()
    load(tmp_path, FIXED)
    arr = var(None, "arr")
    assert arr.dataType == 1
    set_value(-1, arr, 0.5, 0.25, 0.125, 1e-5, -2.0, 3.0)  # six per call (entry 126)
    step = gt.TVarInfo(arr.id + 6, arr.dataType, arr.name)  # further elements: step the id
    set_value(-1, step, 10.0, 0.1)
    assert gt.GT_Bind(0, fun_id("f"), 0) == 0 and gt.GT_RunThread(0) == 0
    wait_idle((0,))
    assert status(0).error == 0, thread_error(0)
    assert get_value(-1, var(None, "d")) == [19662 / 65536]
    assert get_value(-1, var(None, "e")) == [19661 / 65536]
    assert get_value(-1, var(None, "same")) == [0.0]
    assert get_value(-1, arr, 6)[3] == 1 / 65536  # 1e-5: the nearest step
    want = sum(round(v * 65536) for v in (0.5, 0.25, 0.125, 1e-5, -2.0, 3.0, 10.0, 0.1)) / 65536
    assert get_value(-1, var(None, "total")) == [want]
    assert get_value(-1, gt.TVarInfo(var(None, "idx").id + 2, 0, b"idx")) == [8.0]


def test_variable_access_is_checked(tmp_path):
    open_bare()
    load(tmp_path, FIXED)
    arr = var(None, "arr")
    seven = (c_double * 7)()
    assert gt.GT_GetVarValue(-1, byref(arr), seven, 7) == 7  # count in [1, 6]
    past = gt.TVarInfo(arr.id + 4, arr.dataType, arr.name)
    assert gt.GT_GetVarValue(-1, byref(past), seven, 6) == 7
    assert "runs past arr" in gt.GTE_GetLastError()
    wrong = gt.TVarInfo(arr.id, 0, arr.name)
    assert gt.GT_GetVarValue(-1, byref(wrong), seven, 1) == 7
    assert gt.GT_SetVarValue(-1, byref(arr), (c_double * 1)(40000.0), 1) == 7
    assert gt.GT_GetVarValue(32, byref(arr), seven, 1) == 7  # pages -1..31
    info = gt.TVarInfo()
    assert gt.GT_GetVarId(None, "nope", byref(info)) == 1
    assert gt.GT_GetVarId("nofunction", "i", byref(info)) == 1
    assert gt.GT_GetVarId("f", "i", byref(info)) == 0 and info.id == 0


# --- GT functions from programs: axes --------------------------------------------------------
MOVE = """\
// one function bound to two threads: each moves its axis (10.3.5: homing several axes)
int moved;
int move(int axis, int target)
{
    double prm[4];
    int sts;
    int clk;
    int moving;
    int one;
    int sh;
    long mask;

    GT_AxisOn(axis);
    GT_PrfTrap(axis);
    GT_GetTrapPrm(axis, prm);
    prm[0] = 0.5;
    prm[1] = 0.5;
    GT_SetTrapPrm(axis, prm);
    GT_SetVel(axis, 10.0);
    GT_SetPos(axis, target);
    one = 1;
    sh = axis - 1;
    mask = one << sh;
    GT_Update(mask);
wait:
    GT_GetSts(axis, &sts, 1, &clk);
    moving = sts & 0x400;
    if(moving) goto wait;
    moved = moved + 1;
    return target;
}
"""


@pytest.mark.long
def test_threads_bound_to_one_function_move_two_axes_at_the_same_time(tmp_path):
    bring_up(clock="lockstep")
    load(tmp_path, MOVE)
    fid = fun_id("move")
    axis, target = var("move", "axis"), var("move", "target")
    for thread, (ax, tg) in enumerate([(1, 3000), (2, -2000)]):
        assert gt.GT_Bind(thread, fid, thread) == 0
        set_value(thread, axis, ax)
        set_value(thread, target, tg)
    assert gt.GT_RunThread(0) == 0 and gt.GT_RunThread(1) == 0
    both_moving = False
    vel = c_double()
    for _ in range(3000):
        if not (status(0).run or status(1).run):
            break
        gt.GTE_Wait(1)
        v = []
        for ax in (1, 2):
            gt.GT_GetPrfVel(ax, byref(vel), 1, None)
            v.append(vel.value)
        both_moving |= all(abs(x) > 1 for x in v)
    assert both_moving
    for thread, tg in ((0, 3000), (1, -2000)):
        st = status(thread)
        assert (st.run, st.error, st.result) == (0, 0, tg), thread_error(thread)
    pos = c_double()
    for ax, tg in ((1, 3000), (2, -2000)):
        assert gt.GT_GetPrfPos(ax, byref(pos), 1, None) == 0 and pos.value == tg
    assert get_value(-1, var(None, "moved")) == [2.0]


def test_a_gt_call_refused_in_a_program_stops_the_thread_with_its_code(tmp_path):
    bring_up(clock="lockstep")
    load(tmp_path, "int f()\n{\n    GT_PrfTrap(1);\n    GT_SetVel(1, -5.0);\n    return 1;\n}\n")
    gt.GT_Bind(3, fun_id("f"), 9)
    gt.GT_RunThread(3)
    wait_idle((3,))
    st = status(3)
    assert (st.run, st.error, st.line, st.result) == (0, 7, 4, 0.0)
    assert "GT_SetVel returned 7" in thread_error(3)


def test_a_program_reads_the_clock_and_delays(tmp_path):
    open_bare()
    gt.GTE_Wait(7)
    src = """\
int t0;
int t1;
int f()
{
    int loop;
    GT_GetClock(&t0, &loop);
    GT_Delay(20);
    GT_GetClock(&t1, &loop);
    return 0;
}
"""
    load(tmp_path, src)
    gt.GT_Bind(0, fun_id("f"), 0)
    gt.GT_RunThread(0)
    wait_idle((0,))
    t0, t1 = get_value(-1, var(None, "t0"))[0], get_value(-1, var(None, "t1"))[0]
    assert t0 == 7 and t1 == 27


# --- runtime errors, binding rules, lifetime -------------------------------------------------
def test_division_by_zero_and_index_out_of_range(tmp_path):
    open_bare()
    src = """\
int a[4];
int k;
int div(int x)
{
    int y;
    y = 100 / x;
    return y;
}
int get()
{
    int v;
    v = a[k];
    return v;
}
"""
    load(tmp_path, src)
    gt.GT_Bind(0, fun_id("div"), 0)
    gt.GT_Bind(1, fun_id("get"), 1)
    set_value(-1, var(None, "k"), -1)
    gt.GT_RunThread(0)
    gt.GT_RunThread(1)
    wait_idle((0, 1))
    assert (status(0).error, status(0).line) == (101, 6)
    assert (status(1).error, status(1).line) == (102, 12)
    assert "division by zero" in thread_error(0)
    assert "index -1 out of range 0..3" in thread_error(1)


def test_binding_and_thread_control_return_codes(tmp_path):
    open_bare()
    assert gt.GT_Bind(0, 0, 0) == 1  # nothing downloaded
    assert gt.GT_RunThread(0) == 1
    assert gt.GT_GetFunId("add", byref(c_short())) == 1
    assert status(0).run == 0
    load(tmp_path, BUSY)
    set_value(-1, var(None, "n"), 100_000)
    assert gt.GT_RunThread(4) == 1 and "not bound" in gt.GTE_GetLastError()
    assert gt.GT_Bind(32, 0, 0) == 7 and gt.GT_Bind(0, 0, 32) == 7
    assert gt.GT_Bind(0, 5, 0) == 7  # no function 5
    assert gt.GT_Bind(0, 0, 0) == 0
    assert gt.GT_Bind(1, 0, 0) == 1 and "page 0 belongs to thread 0" in gt.GTE_GetLastError()
    assert gt.GT_PauseThread(0) == 1  # not running
    assert gt.GT_RunThread(0) == 0 and gt.GT_RunThread(0) == 1
    assert gt.GT_Bind(0, 0, 3) == 1  # running
    gt.GTE_Wait(2)
    assert gt.GT_PauseThread(0) == 0 and status(0).run == 2
    line = status(0).line
    gt.GTE_Wait(5)
    assert status(0).line == line
    assert gt.GTN_RunThread(1, 0) == 0 and status(0).run == 1  # resumed, the GTN twin
    assert gt.GT_StopThread(0) == 0 and status(0).run == 0
    assert gt.GT_StopThread(0) == 0
    assert gt.GT_RunThread(0) == 0
    assert gt.GT_Reset() == 0 and status(0).run == 0  # GT_Reset stops every thread
    assert gt.GT_RunThread(0) == 0  # the download and the binding stay


def test_the_download_is_lost_at_close(tmp_path):
    open_bare()
    load(tmp_path, SUM)
    assert fun_id("add") == 0
    gt.GT_Close()
    open_bare()
    assert gt.GT_GetFunId("add", byref(c_short())) == 1
    assert "GT_Download" in gt.GTE_GetLastError()


def test_download_return_codes(tmp_path):
    open_bare()
    assert gt.GT_Download(str(tmp_path / "none.bin")) == 2007
    bin_path = compile_text(tmp_path, SUM, "sum.c")
    bin_path.with_suffix(".ini").unlink()
    assert gt.GT_Download(str(bin_path)) == 2008
    (tmp_path / "junk.bin").write_bytes(b"not a program")
    (tmp_path / "junk.ini").write_text("[program]\nformat = 1\nbuild = x\n")
    assert gt.GT_Download(str(tmp_path / "junk.bin")) == 2008
    many = "".join(f"int f{k}()\n{{\n    return {k};\n}}\n" for k in range(33))
    assert gt.GT_Download(str(compile_text(tmp_path, many, "many.c"))) == 7


# --- GT_Compile and gtecat compile -----------------------------------------------------------
def test_compile_errors_come_back_with_line_and_message(tmp_path):
    src = tmp_path / "bad.c"
    src.write_text("int f(int a)\n{\n    int b;\n    b = a + a + a;\n    return b;\n}\n")
    info = gt.TCompileInfo()
    assert gt.GT_Compile(str(src), byref(info)) == 1
    assert info.pFileName == str(src).encode()
    assert info.pLineNo[0] == 4
    assert b"only two operands" in info.pMessage
    assert "bad.c:4: only two operands" in gt.GTE_GetLastError()
    assert not (tmp_path / "bad.bin").exists() and not (tmp_path / "bad.ini").exists()
    good = tmp_path / "good.c"
    good.write_text(SUM)
    assert gt.GT_Compile(str(good), byref(info)) == 0
    assert (info.pLineNo[0], info.pMessage) == (0, b"")
    assert gt.GT_Compile(str(tmp_path / "none.c"), byref(info)) == 1
    assert b"cannot read" in info.pMessage


def test_compile_needs_no_open_controller(tmp_path):
    gt.GT_Close()
    src = tmp_path / "s.c"
    src.write_text(SUM)
    assert gt.GT_Compile(str(src), byref(gt.TCompileInfo())) == 0


def test_cli_compile(tmp_path, capsys):
    good, bad = tmp_path / "good.c", tmp_path / "bad.c"
    good.write_text(SUM)
    bad.write_text("int f()\n{\n    x = 1;\n    while(x) { }\n}\n")
    assert cli(["compile", str(good)]) == 0
    assert (tmp_path / "good.bin").is_file() and "1 function(s)" in capsys.readouterr().out
    assert cli(["compile", str(bad)]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err == [
        f"{bad}:4: while loops are not supported: write them with a label, "
        "`cc = ...;`, `if(cc) goto label;` and `goto label;` (10.4.3)"
    ]
    assert cli(["compile", "--check", "--list", str(good)]) == 0
    assert "JUMP_IF" in capsys.readouterr().out


# --- MRAM ------------------------------------------------------------------------------------
def test_mram_round_trip_takes_controller_time(tmp_path):
    store = tmp_path / "m.mram"
    open_bare(mram=str(store))
    words = (c_int16 * 24)(*range(-12, 12))
    assert gt.GT_SetMRAMData(4072, words, 24) == 0
    assert gt.GT_StartAccessMRAM(4072, 24, 1) == 0
    sts = c_short(9)
    assert gt.GT_GetMRAMStatus(byref(sts)) == 0 and sts.value == 0
    gt.GTE_Wait(1)
    assert gt.GT_GetMRAMStatus(byref(sts)) == 0 and sts.value == 0
    gt.GTE_Wait(1)
    assert gt.GT_GetMRAMStatus(byref(sts)) == 0 and sts.value == 1
    assert store.is_file()
    gt.GT_Close()
    open_bare(mram=str(store))
    back = (c_int16 * 24)()
    assert gt.GT_GetMRAMData(4072, back, 24) == 0 and list(back) == [0] * 24  # a new buffer
    assert gt.GT_StartAccessMRAM(4072, 24, 0) == 0
    gt.GTE_Wait(2)
    assert gt.GT_GetMRAMData(4072, back, 24) == 0 and list(back) == list(range(-12, 12))


def test_mram_arguments_are_checked():
    open_bare()
    w = (c_int16 * 25)()
    assert gt.GT_SetMRAMData(0, w, 25) == 7  # at most 24 words per call
    assert gt.GT_SetMRAMData(4090, w, 10) == 7  # past the buffer
    assert gt.GT_GetMRAMData(4096, w, 1) == 7
    assert gt.GT_StartAccessMRAM(0, 4097, 1) == 7
    assert gt.GT_StartAccessMRAM(1, 4096, 1) == 7
    assert gt.GT_StartAccessMRAM(0, 10, 2) == 7
    assert gt.GT_StopAccessMRAM() == 0


def test_mram_default_store_is_beside_the_log(tmp_path, monkeypatch):
    monkeypatch.delenv("GTECAT_MRAM")
    log = tmp_path / "logs" / "Gecat.log"
    log.parent.mkdir()
    open_bare(log=str(log))
    gt.GT_SetMRAMData(0, (c_int16 * 1)(5), 1)
    gt.GT_StartAccessMRAM(0, 1, 1)
    gt.GTE_Wait(3)
    assert (tmp_path / "logs" / "Gecat.mram").is_file()


# --- GetMacAddress ---------------------------------------------------------------------------
def test_mac_address_is_stable_per_configuration():
    def mac(eni: str, adapter: int = 0, fn=gt.GetMacAddress) -> bytes:
        gt.GT_Close()
        assert gt.GT_Open(eni=str(EXAMPLES / eni), clock="lockstep", log="") == 0
        buf = (c_ubyte * 8)()
        assert fn(adapter, buf, 8) == 0
        return bytes(buf)

    a = mac("manual_fig5_2.eni")
    assert a[:3] == b"\x02\x47\x54" and a[6:] == b"\0\0"
    assert mac("manual_fig5_2.eni") == a
    assert mac("manual_fig5_2.eni", fn=gt.GT_GetMacAddress) == a
    assert mac("manual_fig5_4.eni") != a
    assert mac("manual_fig5_2.eni", 1) != a
    small = (c_ubyte * 5)()
    assert gt.GetMacAddress(0, small, 5) == 7
    assert gt.GetMacAddress(2, (c_ubyte * 6)(), 6) == 7
    assert gt.GTN_GetMacAddress(1, 0, (c_ubyte * 6)(), 6) == 0


def test_thread_status_structure_and_long_pointers(tmp_path):
    """GT calls from programs with long* / unsigned long* out pointers (GT_GetEcatEncPos)."""
    bring_up(clock="lockstep")
    src = "int enc;\nint f()\n{\n    GT_GetEcatEncPos(1, &enc);\n    return enc;\n}\n"
    load(tmp_path, src)
    gt.GT_Bind(0, fun_id("f"), 0)
    gt.GT_RunThread(0)
    wait_idle((0,))
    mine = c_long()
    assert gt.GT_GetEcatEncPos(1, byref(mine)) == 0
    assert status(0).error == 0 and status(0).result == mine.value


def test_program_calls_leave_the_hosts_last_error_alone(tmp_path):
    open_bare("auto", call_latency_us=1000.0)  # every host call runs a program cycle
    src = "int c;\nint f()\n{\n    int l;\ntop:\n    GT_GetClock(&c, &l);\n    goto top;\n}\n"
    load(tmp_path, src)
    gt.GT_Bind(0, fun_id("f"), 0)
    gt.GT_RunThread(0)
    gt.GTE_Wait(5)
    assert gt.GT_Bind(0, 0, 1) == 1  # running; the call's latency runs the program's calls
    assert "running" in gt.GTE_GetLastError()
    assert get_value(-1, var(None, "c"))[0] >= 5


def test_programs_call_the_gtn_twins_too(tmp_path):
    open_bare()
    gt.GTE_Wait(3)
    src = """\
int t;
int f()
{
    int loop;
    GTN_Delay(1, 5);
    GTN_GetClock(1, &t, &loop);
    return 0;
}
"""
    load(tmp_path, src)
    gt.GT_Bind(0, fun_id("f"), 0)
    gt.GT_RunThread(0)
    wait_idle((0,))
    assert status(0).error == 0, thread_error(0)
    assert get_value(-1, var(None, "t")) == [8.0]
    bad = tmp_path / "bad.c"
    bad.write_text("int f()\n{\n    GTN_Open(1, 0, 1);\n    return 0;\n}\n")
    assert gt.GT_Compile(str(bad), byref(gt.TCompileInfo())) == 1
    assert "GTN_Open belongs to the host" in gt.GTE_GetLastError()
