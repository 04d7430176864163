"""Bring-up (issue 12 item 4): GT_IsEcatReady after a failed or missing init, and the
GT_StartEcatComm gate on motion (manual entries 79, 80, 129; example 5-5).
"""

from __future__ import annotations

import contextlib
import io
import re
import runpy
import shutil
import signal
from ctypes import byref, c_long, c_short, c_ubyte
from pathlib import Path

import pytest

from gtecat import gt
from tests.conftest import EXAMPLES, ROOT

from .conftest import bring_up

FIG52 = str(EXAMPLES / "manual_fig5_2.eni")


def readme_loop() -> tuple[int, int]:
    """The README's polling loop, verbatim, with a bound: (polls, last return code)."""
    status, polls, rc = c_short(), 0, 0
    while (rc := gt.GT_IsEcatReady(byref(status))) == 0 and status.value != 1:
        polls += 1
        assert polls < 100_000, "the README loop would hang"
    return polls, rc


def test_before_any_init_is_ready_returns_1_with_the_reason():
    assert gt.GT_Open(eni=FIG52, log="", clock="lockstep") == 0
    st = c_short(7)
    assert gt.GT_IsEcatReady(byref(st)) == 1 and st.value == 0
    assert "call GT_InitEcatComm first" in gt.GTE_GetLastError()
    assert readme_loop() == (0, 1)


def test_no_eni_minus_9_then_is_ready_returns_1_with_the_init_reason(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # outside the repository: no ./Gecat.eni
    assert gt.GT_Open(log="") == 0
    assert gt.GT_InitEcatComm() == -9
    st = c_short(7)
    assert gt.GT_IsEcatReady(byref(st)) == 1 and st.value == 0
    reason = gt.GTE_GetLastError()
    assert "GT_InitEcatComm failed (-9" in reason and "no ENI file" in reason
    assert "Gecat.eni" in reason
    assert readme_loop() == (0, 1)
    # the cause fixed, the same controller comes up
    shutil.copy(FIG52, tmp_path / "Gecat.eni")
    assert gt.GT_InitEcatComm() == 0
    polls, rc = readme_loop()
    assert rc == 0 and polls > 0


def test_an_eni_path_that_is_a_folder_says_so_and_names_the_file_inside(tmp_path):
    shutil.copy(EXAMPLES / "manual_fig5_4.eni", tmp_path / "bus.eni")
    assert gt.GT_Open(eni=str(tmp_path), log="", clock="lockstep") == 0
    assert gt.GT_InitEcatComm() == -9
    reason = gt.GTE_GetLastError()
    assert f"{tmp_path} is a folder, not an ENI file (it holds bus.eni)" in reason
    assert str(tmp_path / "bus.eni") in reason and "no ENI file" not in reason


def _empty_eni(tmp_path) -> str:
    """The figure 5-2 ENI with its slaves taken out (`gtecat eni new` refuses to write one)."""
    text = re.sub(r"<Slave>.*?</Slave>\s*", "", Path(FIG52).read_text(), flags=re.S)
    (tmp_path / "e.eni").write_text(text)
    return str(tmp_path / "e.eni")


@pytest.mark.parametrize("where", ["eni", "bus"])
def test_an_emulated_bus_without_slaves_is_minus_10_naming_the_file_not_a_cable(tmp_path, where):
    empty = _empty_eni(tmp_path)
    # the ENI itself lists no slaves, or the hardware description (GTECAT_BUS) does
    opts = {"eni": empty} if where == "eni" else {"eni": FIG52, "bus": empty}
    assert gt.GT_Open(log="", clock="lockstep", **opts) == 0
    assert gt.GT_InitEcatComm() == -10
    reason = gt.GTE_GetLastError()
    what = "the ENI" if where == "eni" else "the hardware description"
    assert f"{what} {empty} lists no slaves, so the emulated bus is empty" in reason
    assert "exported for the machine" in reason and "cabling" not in reason


def test_mismatch_minus_8_then_is_ready_returns_1_naming_the_slave():
    assert gt.GT_Open(eni=FIG52, bus=str(EXAMPLES / "twelve_axes.eni"), log="") == 0
    assert gt.GT_InitEcatComm() == -8
    assert readme_loop() == (0, 1)
    reason = gt.GTE_GetLastError()
    assert "GT_IsEcatReady returned 1" in reason and "(-8: slave 2" in reason


def test_after_terminate_is_ready_returns_1():
    bring_up(clock="lockstep")
    assert gt.GT_TerminateEcatComm() == 0
    st = c_short(7)
    assert gt.GT_IsEcatReady(byref(st)) == 1 and st.value == 0
    assert "GT_TerminateEcatComm" in gt.GTE_GetLastError()


def test_while_coming_up_is_ready_returns_0_with_status_0():
    assert gt.GT_Open(eni=FIG52, log="", clock="lockstep") == 0
    assert gt.GT_InitEcatComm() == 0
    st = c_short(7)
    assert gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 0  # OP a few cycles later
    gt.GTE_Wait(20)
    assert gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1


def test_readme_first_script_ends_when_run_outside_the_repository(tmp_path, monkeypatch):
    """The checkers' finding: in a folder without the ENI (-9) the README's loop hung.  The
    script runs in this process (a child would only add an interpreter start), in an empty
    folder, under a 60 s alarm."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    block = re.search(r"## A first script.*?```python\n(.*?)```", text, re.S)
    assert block is not None and "GT_IsEcatReady" in block.group(1)
    script = tmp_path / "first.py"
    script.write_text(block.group(1))
    monkeypatch.chdir(tmp_path)

    def hung(*_: object) -> None:
        raise TimeoutError("the README's first script still ran after 60 s")

    out = io.StringIO()
    old = signal.signal(signal.SIGALRM, hung)
    signal.alarm(60)
    gt.GT_Close()
    try:
        with contextlib.redirect_stdout(out):
            runpy.run_path(str(script), run_name="__main__")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)
        gt.GT_Close()
    assert "returned 1" in out.getvalue()  # a GT call's reason: not established


# --- entry 129: motion only after GT_StartEcatComm ----------------------------------------------
def _up_without_start() -> None:
    assert gt.GT_Open(eni=FIG52, log="", clock="lockstep") == 0
    assert gt.GT_InitEcatComm() == 0
    gt.GTE_Wait(20)
    st = c_short()
    assert gt.GT_IsEcatReady(byref(st)) == 0 and st.value == 1


def test_axis_on_before_start_ecat_comm_returns_1_with_the_reason():
    _up_without_start()
    assert gt.GT_AxisOn(1) == 1
    reason = gt.GTE_GetLastError()
    assert "GT_StartEcatComm" in reason and "entry 129" in reason
    # the drive was not touched
    assert gt.GTE_Slave(0).channel(0).state.name != "OPERATION_ENABLED"
    assert gt.GT_StartEcatComm() == 0
    assert gt.GT_AxisOn(1) == 0, gt.GTE_GetLastError()


@pytest.mark.parametrize("start", ["update", "homing"])
def test_every_motion_start_before_start_ecat_comm_is_refused(start):
    """GT_Update / GT_StartEcatHoming need the servo on, which only GT_AxisOn gives."""
    _up_without_start()
    assert gt.GT_AxisOn(1) == 1
    if start == "update":
        prm = gt.TTrapPrm()
        assert gt.GT_PrfTrap(1) == 0
        assert gt.GT_GetTrapPrm(1, byref(prm)) == 0
        assert gt.GT_SetPos(1, 1000) == 0 and gt.GT_SetVel(1, 10) == 0
        assert gt.GT_Update(1) == 1
        assert "GT_AxisOn" in gt.GTE_GetLastError()
    else:
        assert gt.GT_SetHomingMode(1, 6) == 0
        assert gt.GT_SetEcatHomingPrm(1, 37, 1000, 100, 10000, 0, 0) == 0
        assert gt.GT_StartEcatHoming(1) == 1
        assert "GT_AxisOn" in gt.GTE_GetLastError()


def test_a_new_init_needs_a_new_start():
    bring_up(clock="lockstep")
    assert gt.GT_TerminateEcatComm() == 0
    assert gt.GT_InitEcatComm() == 0
    gt.GTE_Wait(20)
    assert gt.GT_AxisOn(1) == 1 and "GT_StartEcatComm" in gt.GTE_GetLastError()
    assert gt.GT_StartEcatComm() == 0 and gt.GT_AxisOn(1) == 0


def test_reads_and_settings_work_between_init_and_start():
    """Bring-up code reads and configures before it starts motion control."""
    _up_without_start()
    s = c_long()
    assert gt.GT_GetSts(1, byref(s)) == 0
    assert gt.GT_GetEcatEncPos(1, byref(s)) == 0
    buf = (c_ubyte * 2)()
    assert gt.GT_GetEcatRawData(6, 2, buf) == 0
    assert gt.GT_SetPosErr(1, 1000) == 0
