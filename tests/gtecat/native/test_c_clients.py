"""C and C++ programs linked with libgts, compiled exactly as a user would and run with
nothing started before: ``GT_Open`` starts a private controller that ends with them."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from .conftest import (
    C_DIR,
    compile_client,
    native_env,
    needs_cc,
    needs_cxx,
    run_client,
)

# the compiled clients serve the module: under pytest-xdist (--dist loadgroup) one worker
pytestmark = [needs_cc, pytest.mark.xdist_group("c_clients")]


@pytest.fixture(scope="module")
def clock_probe(libgts, tmp_path_factory):
    out = tmp_path_factory.mktemp("c") / "clock_probe"
    return compile_client(C_DIR / "clock_probe.c", out, "gcc")


def test_vendor_gtn_sequence_from_c(gtn_sequence, tmp_path):
    r, v = run_client(gtn_sequence, env=native_env(), cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    assert v["done"] == "1", r.stdout + r.stderr
    # bring-up, polled with usleep as the vendor demo does
    assert (v["open"], v["init"], v["ready"], v["start"]) == ("0", "0", "1", "0")
    # opening twice: -6 with Python's reason (bus_calls.GT_Open), the first open stays
    assert v["open_twice"] == "-6" and "already open" in v["open_twice_reason"]
    assert int(v["ready_polls"]) < 100
    # declared-only functions (assembled on x86-64): each says which it is
    assert v["declared_arc"] == v["declared_struct"] == "8" and v["declared_stack"] == "1"
    assert "GTN_ArcXYCOverride2 is declared" in v["declared_arc_reason"]
    # a 200 ms usleep lets at least 200 ms of controller time pass (the wall floor)
    assert int(v["slept_ms"]) >= 200
    # raw data: slave 2's outputs at 32 read back; its inputs at 34 cannot be written
    assert (v["raw_write"], v["raw_read"], v["raw_back"]) == ("0", "0", str(0x3CA5))
    assert v["raw_write_inputs"] == "7"
    assert (v["pdo_length_rc"], v["pdo_length"]) == ("0", "40")
    # servo on, Trap move: planned and encoder positions reach the target
    assert (v["clrsts"], v["axis_on"], v["enabled"]) == ("0", "0", "1")
    for k in ("prftrap", "gettrap", "settrap", "setvel", "setpos", "update"):
        assert v[k] == "0", k
    assert int(v["move_polls"]) < 1000
    assert (v["getprfpos"], v["getencpos"]) == ("0", "0")
    assert v["prfpos"] == "20000"
    assert v["encpos"] == "20000"
    assert (v["ecatencpos_rc"], v["ecatencpos"]) == ("0", "20000")
    # SDO: a good upload, then the abort code of an object that does not exist
    assert (v["sdo_up"], v["sdo_size"], v["sdo_abort"]) == ("0", "2", "0")
    assert v["sdo_bad"] == "1"
    assert int(v["sdo_bad_abort"]) == 0x06020000
    assert "0x06020000" in v["sdo_bad_reason"]
    assert v["sdo_nulls"] == "0"
    assert (v["sdo_down"], v["sdo_down_abort"]) == ("0", "0")
    # NULL: optional pointers are fine, a required one is 7 with the reason
    assert v["null_optional"] == "0"
    assert v["null_required"] == "7"
    assert "pSts is NULL" in v["null_required_reason"]
    assert (v["slaves_one_ptr"], v["slaves"]) == ("0", "4")
    # bad values: the codes Python gives
    assert v["bad_axis"] == "7"
    assert v["bad_core"] == "7"
    assert "core 7" in v["bad_core_reason"]
    assert v["bad_count"] == "7"
    assert v["sts_two"] == "0"
    assert v["version_rc"] == "0"
    assert v["version"] == "010 261201 010 261201"  # table 11-3
    assert v["last_error_null"] == "7"
    # GT_Close detaches: -1 until the next GT_Open, which finds the controller again
    assert (v["close"], v["after_close"]) == ("0", "-1")
    assert "GT_Open" in v["after_close_reason"]
    assert (v["reopen"], v["reopen_sts"]) == ("0", "0")


def test_the_private_controller_ends_with_the_program(gtn_sequence_on_its_controller_process):
    # (GTECAT_INPROCESS=0: the controller process; by default it runs in the program.  The
    # run is test_inprocess's too; its folder was made for it, so nothing ran there before)
    r, v, cwd = gtn_sequence_on_its_controller_process
    assert v.get("done") == "1", r.stdout + r.stderr
    deadline = time.monotonic() + 10
    while _controllers(cwd) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _controllers(cwd)


def test_the_scheduling_setting_of_gtecat_ini_reaches_the_private_controller(
    gtn_sequence, tmp_path
):
    """GTECAT_RT_PRIORITY may be written in gtecat.ini, which only the library reads: it
    hands the setting to the controller it starts (an unreadable one: the controller says
    so and does not start)."""
    ini = tmp_path / "gtecat.ini"
    ini.write_text("rt_priority = high\n")
    r, v = run_client(gtn_sequence, env=native_env(GTECAT_INI=str(ini)), cwd=tmp_path)
    assert v.get("open") == "-1", r.stdout + r.stderr
    assert "--rt-priority: 'high': a priority 1-99, auto or off" in r.stderr


def _controllers(cwd: Path) -> set[int]:
    """Private controllers running in ``cwd``: the program's own (it inherits the program's
    folder), never another test's or another run's on the same machine (xdist workers and
    other users start private controllers of their own at any time)."""
    import os

    out = set()
    for pid in os.listdir("/proc"):
        if not pid.isdigit():
            continue
        try:
            cmd = open(f"/proc/{pid}/cmdline", "rb").read().split(b"\0")
            where = os.readlink(f"/proc/{pid}/cwd")
        except OSError:
            continue
        if b"controller" in cmd and b"--private" in cmd and b"gtecat" in cmd:
            if Path(where) == cwd.resolve():
                out.add(int(pid))
    return out


@pytest.mark.long
def test_auto_with_the_wall_floor(clock_probe, tmp_path):
    r, v = run_client(clock_probe, env=native_env(), cwd=tmp_path)
    assert v.get("open") == "0", r.stdout + r.stderr
    assert int(v["sleep_ms"]) >= 300  # controller time never falls behind the wall
    assert int(v["wait_ms"]) >= 100
    assert int(v["poll2000_ms"]) >= 100  # 2000 calls x 50 us of virtual latency


@pytest.mark.long
def test_deterministic_auto_without_the_floor(clock_probe, tmp_path):
    r, v = run_client(clock_probe, env=native_env(GTECAT_WALL_FLOOR="0"), cwd=tmp_path)
    assert v.get("open") == "0", r.stdout + r.stderr
    assert int(v["sleep_ms"]) <= 1  # only the GetClock call's latency
    assert 100 <= int(v["wait_ms"]) <= 101
    assert 100 <= int(v["poll2000_ms"]) <= 101


def test_lockstep_from_c(clock_probe, tmp_path):
    r, v = run_client(clock_probe, env=native_env(GTECAT_CLOCK="lockstep"), cwd=tmp_path)
    assert v.get("open") == "0", r.stdout + r.stderr
    assert v["sleep_ms"] == "0"
    assert v["wait_ms"] == "100"
    assert v["poll2000_ms"] == "0"


def test_a_missing_python_is_a_clear_error(clock_probe, tmp_path):
    env = native_env(GTECAT_PYTHON=str(tmp_path / "no-python"))
    r, _ = run_client(clock_probe, env=env, cwd=tmp_path, timeout=60)
    assert r.returncode == 1
    assert "open -1" in r.stdout


@needs_cxx
@pytest.mark.long
def test_seed_002_shaped_cpp_program(motion_demo, tmp_path):
    r, v = run_client(motion_demo, env=native_env(), cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    assert v["axes"] == "2 enabled 1"
    assert v["home"] == "status 3"
    assert v["moved"] == "prf 30000 enc 30000"
    assert v["done"] == ""


@needs_cxx
@pytest.mark.long
def test_the_vendor_gtn_open_close_and_pdo_data_shapes_compile_and_run(libgts, tmp_path):
    """GTN_Open(5) / GTN_Open() / GTN_Close() and a three-parameter GTN_GetEcatAxisPdoData,
    as the vendor's GTN header declares them (an outside check found our core-first forms
    refused by vendor demo code)."""
    exe = compile_client(C_DIR / "vendor_gtn_shapes.cpp", tmp_path / "shapes", "g++")
    r, v = run_client(exe, env=native_env(), cwd=tmp_path)
    assert r.returncode == 0 and v.get("done") == "1", r.stdout + r.stderr
    assert (v["open5"], v["init"], v["ready"], v["start"]) == ("0", "0", "1", "0")
    assert (v["pdo_rc"], v["sw_nonzero"]) == ("0", "1")
    assert (v["close"], v["open_default"], v["close2"]) == ("0", "0", "0")


@pytest.fixture(scope="module")
def slice_probe(libgts, tmp_path_factory):
    out = tmp_path_factory.mktemp("c") / "slice_probe"
    return compile_client(C_DIR / "slice_probe.c", out, "gcc")


def _kernel_slices() -> bool:
    """This kernel reports a SCHED_OTHER thread's slice (Linux 6.12 and later)."""
    from gtecat import scheduling

    calls = scheduling._sched_attr_calls()
    attr = calls[0]() if calls else None
    return bool(attr and attr[1] == 0 and attr[5])


def test_each_calling_thread_asks_for_the_slice_it_is_given(slice_probe, tmp_path):
    """With GTECAT_SLICE_US=100 (or slice_us = 100 in gtecat.ini) libgts asks once per
    thread, at its first call, for a 100 us slice (where the kernel has custom slices;
    elsewhere the thread is left as it was), which threads the thread starts afterwards
    inherit; by default, or with 0, every thread is left alone."""
    ini = tmp_path / "gtecat.ini"
    ini.write_text("slice_us = 100\n")
    for env in (native_env(GTECAT_SLICE_US="100"), native_env(GTECAT_INI=str(ini))):
        r, v = run_client(slice_probe, env=env, cwd=tmp_path)
        assert r.returncode == 0 and v["call"] == v["thread_call"] == "0", r.stdout + r.stderr
        if not _kernel_slices():
            assert (v["after"], v["thread_after"]) == (v["before"], v["thread_before"])
            return
        assert int(v["thread_before"]) > 100000 and int(v["before"]) > 100000  # the default
        assert (v["after"], v["thread_after"], v["child_thread"]) == ("100000",) * 3
    for env in (native_env(), native_env(GTECAT_SLICE_US="0")):
        r, v = run_client(slice_probe, env=env, cwd=tmp_path)
        assert (v["after"], v["thread_after"]) == (v["before"], v["thread_before"]), r.stdout
        assert v["child_thread"] == v["before"]
