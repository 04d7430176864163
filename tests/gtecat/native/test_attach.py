"""``from gtecat import gt`` attached to a controller process (``GT_Open(controller=...)``,
``GTECAT_CONTROLLER``) and the field side over the socket (:mod:`gtecat.native.field`).

The controller here is a real ``gtecat controller`` process; the test's own gt session
attaches to it, the way a pytest test drives the machine while the user's compiled
program runs against the same controller.
"""

from __future__ import annotations

import ctypes
import os
import subprocess
import sys
from ctypes import byref, c_double, c_int32, c_long, c_short, c_ubyte

import numpy as np
import pytest

from gtecat import gt
from gtecat.gt import _core
from gtecat.native import client
from gtecat.native.client import field
from gtecat.native.server import wait_for

from .conftest import FIG5_2, native_env, needs_cxx


def _start_controller(address: str, clock: str, cwd) -> subprocess.Popen:
    env = native_env(GTECAT_CLOCK=clock)
    proc = subprocess.Popen(
        [sys.executable, "-m", "gtecat", "controller", "--listen", address, "--eni", str(FIG5_2)],
        env=env,
        cwd=cwd,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        wait_for(address, 60)
    except TimeoutError:
        proc.kill()
        raise
    return proc


@pytest.fixture
def controller(tmp_path, monkeypatch):
    """A ``gtecat controller`` process (lockstep, figure 5-2 bus); yields its address."""
    monkeypatch.delenv("GTECAT_CONTROLLER", raising=False)
    _core.close_all()
    address = f"unix:{tmp_path}/ctl.sock"
    proc = _start_controller(address, "lockstep", tmp_path)
    yield address, proc
    _core.close_all()
    _end(proc)


def _end(proc: subprocess.Popen) -> None:
    """End a controller as a user would (SIGTERM): it removes its inspection files; SIGKILL
    left them in the runtime folder for `gtecat ps` to sweep."""
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(30)
        except subprocess.TimeoutExpired:
            proc.kill()
    proc.wait()


def _bring_up() -> None:
    assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
    ready = c_short()
    for _ in range(200):
        assert gt.GTE_Wait(5) == 0
        if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
            break
    assert ready.value == 1
    assert gt.GT_StartEcatComm() == 0


def test_attached_calls_return_the_controllers_codes_and_write_the_callers_memory(controller):
    address, _ = controller
    assert gt.GT_Open(controller=address) == 0
    assert _core.SESSION.remote is not None and not _core.SESSION.controllers
    _bring_up()
    assert gt.GT_AxisOn(1) == 0 and gt.GTE_Wait(20) == 0
    # out pointers of every habit: byref, a c_int32 array for long *, a list, numpy
    sts = c_long(-1)
    assert gt.GT_GetSts(1, byref(sts)) == 0 and sts.value & (1 << 9)  # servo on
    two = (c_int32 * 2)(-1, -1)
    assert gt.GT_GetSts(1, two, 2) == 0 and two[0] == sts.value and two[1] != -1
    lst: list = []
    assert gt.GT_GetSts(1, lst, 2) == 0 and lst == list(two)
    arr = np.full(2, -1, dtype=np.int64)
    assert gt.GTN_GetSts(1, 1, arr, 2) == 0 and list(arr) == list(two)
    clock = ctypes.c_ulong()
    assert gt.GT_GetClock(byref(clock)) == 0 and clock.value > 0
    # in pointers and structures travel too
    assert gt.GT_PrfTrap(1) == 0
    trap = gt.TTrapPrm()
    assert gt.GT_GetTrapPrm(1, byref(trap)) == 0
    trap.acc, trap.dec = 0.25, 0.5
    assert gt.GT_SetTrapPrm(1, byref(trap)) == 0
    back = gt.TTrapPrm()
    assert gt.GT_GetTrapPrm(1, byref(back)) == 0 and (back.acc, back.dec) == (0.25, 0.5)
    raw = (c_ubyte * 2)(0x5A, 0xA5)
    assert gt.GT_EcatIOWriteOutput(2, 0, 2, raw) == 0 and gt.GTE_Wait(5) == 0
    assert field().get_output(2, 0x7000, 1) == 0x5A
    # bad input: 7 with the controller's reason, memory untouched
    sts.value = -12345
    assert gt.GT_GetSts(99, byref(sts)) == 7 and sts.value == -12345
    assert gt.GTE_GetLastError().startswith("GT_GetSts returned 7: axis=99")
    assert gt.GT_GetSts(1, None) == 7 and "NULL" in gt.GTE_GetLastError()
    assert gt.GTN_GetSts(3, 1, byref(sts)) == 7 and "core 3" in gt.GTE_GetLastError()
    assert gt.GT_SetVel(1, float("nan")) == 7
    assert gt.GT_GetSts(1, byref(sts)) == 0 and gt.GTE_GetLastError() == ""
    pos = c_double()
    assert gt.GT_GetPrfPos(1, byref(pos)) == 0


@pytest.mark.long
def test_open_twice_options_and_the_python_objects_are_refused_clearly(controller):
    address, _ = controller
    assert gt.GT_Open(controller=address, eni=str(FIG5_2)) == 7
    assert "eni" in gt.GTE_GetLastError() and "its own" in gt.GTE_GetLastError()
    assert gt.GT_Open(controller=address, log="") == 0
    assert gt.GT_Open(controller=address) == -6
    assert gt.GT_Open() == -6  # attached: a second open, as in-process
    # a second card of the same controller, on the same connection (gtecat.controller.cards)
    assert gt.GT_SetCardNo(1) == 0 and gt.GT_Open(controller=address) == 0
    assert gt.GT_AxisOn(1) == 7  # card 1's own bus is not up
    assert "bus not initialised" in gt.GTE_GetLastError()
    index = c_short()
    assert gt.GT_GetCardNo(byref(index)) == 0 and index.value == 1
    _bring_up()  # card 1's bus; its field side is its own
    field().inject_fault(0, "alarm")  # the session's current card: 1
    assert gt.GTE_Wait(5) == 0
    sts = c_long()
    assert gt.GT_GetSts(1, byref(sts)) == 0 and sts.value & (1 << 1)  # alarm on card 1
    assert field().drive(0)["error_code"] != 0
    with pytest.raises(client.ControllerError, match="card 2 is not open"):
        field(card=2).drive(0)
    assert gt.GT_Close() == 0 and _core.SESSION.remote is not None  # card 0 still open
    assert gt.GT_SetCardNo(0) == 0
    with pytest.raises(_core.NotOpen, match=r"field\(\)"):
        gt.GTE_Slave(0)
    with pytest.raises(_core.NotOpen, match="attached"):
        gt.GTE_Controller()
    assert gt.GT_Close() == 0 and _core.SESSION.remote is None
    sts = c_long()
    assert gt.GT_GetSts(1, byref(sts)) == -1  # detached: not open
    with pytest.raises(client.ControllerError, match="not attached"):
        field()


@pytest.mark.long
def test_gtecat_controller_in_the_environment_attaches_and_local_does_not(controller, monkeypatch):
    address, _ = controller
    monkeypatch.setenv("GTECAT_CONTROLLER", address)
    assert gt.GT_Open() == 0 and _core.SESSION.remote.address == address
    assert gt.GT_Close() == 0
    assert gt.GT_Open(controller="local", eni=str(FIG5_2), log="") == 0
    assert _core.SESSION.remote is None and 1 in _core.SESSION.controllers
    assert gt.GT_Close() == 0


@pytest.mark.long
def test_a_controller_that_dies_makes_every_call_minus_1_with_the_reason(controller):
    address, proc = controller
    assert gt.GT_Open(controller=address) == 0
    proc.kill()
    proc.wait()
    sts = c_long()
    for _ in range(2):
        assert gt.GT_GetSts(1, byref(sts)) == -1
        assert "controller not responding" in gt.GTE_GetLastError()
    assert gt.GT_Close() == 0 and _core.SESSION.remote is None
    assert gt.GT_Open(controller=address) == -1
    assert "cannot reach" in gt.GTE_GetLastError()


@pytest.mark.long
def test_field_operations_reach_the_machine_and_refuse_with_reasons(controller):
    address, _ = controller
    with field(address) as f:  # no GT_Open yet: nothing to show
        with pytest.raises(client.ControllerError, match="not open"):
            f.slaves()
    assert gt.GT_Open(controller=address) == 0
    _bring_up()
    f = field()
    rows = f.slaves()
    assert [r["state"] for r in rows] == ["OP"] * 4 and rows[0]["axes"] == [1]
    assert f.slaves(2)[0]["name"] == "IO 2"
    assert f.pdos(0)[0]["position"] == 0
    # an IO terminal's input, read back through the GT API
    f.set_input(2, 0x6000, 1, 0x81)
    assert gt.GTE_Wait(5) == 0
    raw = (c_ubyte * 4)()  # slave 2's GT raw region: 2 output bytes, then its 2 inputs
    assert gt.GT_GetEcatRawData(32, 4, raw) == 0 and raw[2] == 0x81
    f.set_input_bit(2, 9, True)
    assert gt.GTE_Wait(5) == 0
    assert gt.GT_GetEcatRawData(32, 4, raw) == 0 and raw[3] == 0x02
    # SDO of a running bus
    assert f.sdo_upload(0, 0x6041, 0) == bytes.fromhex(f"{f.drive(0)['statusword']:04x}")[::-1]
    assert f.sdo_entry(0, 0x6041, 0)["name"]
    # a drive fault and its cause cleared
    assert gt.GT_ClrSts(1) == 0 and gt.GT_AxisOn(1) == 0 and gt.GTE_Wait(20) == 0
    assert f.inject_fault(0, "alarm") > 0
    assert gt.GTE_Wait(10) == 0
    sts = c_long()
    assert gt.GT_GetSts(1, byref(sts)) == 0 and sts.value & (1 << 1)
    assert f.drive(0)["state"] == "FAULT"
    f.clear_injected_fault(0)
    assert gt.GT_ClrSts(1) == 0 and gt.GTE_Wait(10) == 0
    assert gt.GT_GetSts(1, byref(sts)) == 0 and not sts.value & (1 << 1)
    # refusals name the problem
    for call, text in [
        (lambda: f.inject_fault(2, "alarm"), "not a drive"),
        (lambda: f.set_input(0, 0x6000, 1, 1), "not an IO terminal"),
        (lambda: f.set_input(2, 0x1234, 1, 1), "0x1234"),
        (lambda: f.slaves(9), "no slave 9"),
        (lambda: f.call("no_such_op"), "no field operation"),
        (lambda: f.call("drive"), "drive"),
        (lambda: f.trace(["axis7.prf"]), "axis"),
    ]:
        with pytest.raises(client.ControllerError, match=text):
            call()
    assert gt.GT_GetSts(1, byref(sts)) == 0  # the controller is fine


def test_every_field_operation_has_its_python_method():
    from gtecat.native import field as ops

    methods = {n for n in dir(client.Field) if not n.startswith("_")}
    traced = {"trace_start", "trace_read", "trace_stop"}  # through Field.trace / Trace
    assert set(ops.OPS) - traced <= methods


# --- the worked example: a compiled program, a test driving the machine and reading traces --
@needs_cxx
@pytest.mark.long
def test_a_compiled_program_and_an_attached_test_share_one_controller_process(
    motion_demo, tmp_path, monkeypatch
):
    monkeypatch.delenv("GTECAT_CONTROLLER", raising=False)
    gt.GT_Close()
    address = f"unix:{tmp_path}/ctl.sock"
    ctl = _start_controller(address, "auto", tmp_path)
    prog = None
    try:
        assert gt.GT_Open(controller=address) == 0  # the first open opens the controller
        prog = subprocess.Popen(
            [str(motion_demo), "37", "60000"],
            env=native_env(GTECAT_CONTROLLER=address),
            cwd=tmp_path,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        assert prog.stdout is not None
        seen = []
        for line in prog.stdout:
            seen.append(line.strip())
            if line.startswith(("watching", "error")):
                break
        assert seen[-1] == "watching", seen
        f = field()
        trace = f.trace(["axis1.prf", "axis1.sw"])
        sts = c_long()
        assert gt.GT_GetSts(1, byref(sts)) == 0 and sts.value & (1 << 10)  # moving
        assert gt.GTE_Wait(20) == 0
        f.inject_fault(0, "alarm")
        out, err = prog.communicate(timeout=120)
        seen += out.splitlines()
        assert prog.returncode == 0, (seen, err)
        assert "home status 3" in seen and "moved prf 30000 enc 30000" in seen
        watch = next(s for s in seen if s.startswith("watch "))
        assert watch.startswith("watch ret 0 alarm 1"), watch
        data = trace.read()
        assert data.shape[0] >= 20 and data.shape[1] == 3
        assert np.all(np.diff(data[:, 0]) > 0)  # one row per cycle, in controller time
        prf, sw = data[:, 1], data[:, 2].astype(int)
        assert prf[10] > prf[0]  # the move ran while the trace recorded
        assert sw[0] & 0x0F == 0x07 and sw[-1] & 0x08  # operation enabled -> fault
        trace.stop()
        assert gt.GT_GetSts(1, byref(sts)) == 0 and sts.value & (1 << 1)
        f.clear_injected_fault(0)
        assert gt.GT_ClrSts(1) == 0
        assert gt.GT_GetSts(1, byref(sts)) == 0 and not sts.value & (1 << 1)
    finally:
        gt.GT_Close()
        if prog is not None and prog.poll() is None:
            prog.kill()
        _end(ctl)


def test_the_test_suite_never_attaches_by_accident():
    assert os.environ.get("GTECAT_CONTROLLER") is None or _core.SESSION.remote is None
