"""Errors a newcomer meets: one clear line, what to do next, no traceback.

Each error is provoked twice where it can be: from the command line (``error: ...``,
exit 1) and from a script through the GT calls (a return code, and
``gt.GTE_GetLastError()`` saying why).
"""

from __future__ import annotations

import shutil
from ctypes import byref, c_long, c_short
from pathlib import Path

import pytest

from gtecat import gt
from tests.conftest import EXAMPLES
from tests.gtecat.gt.conftest import bring_up

from .conftest import Cli

FIG52 = str(EXAMPLES / "manual_fig5_2.eni")
OTHER_BUS = str(EXAMPLES / "twelve_axes.eni")


def _one_line_error(rc: int, out: str, err: str) -> str:
    assert rc == 1 and out == ""
    assert err.startswith("error: ") and err.count("\n") == 1, err
    assert "Traceback" not in err
    return err


def _last_error_line() -> str:
    text = gt.GTE_GetLastError()
    assert text and "\n" not in text and "Traceback" not in text
    return text


# --- missing ENI --------------------------------------------------------------------------------
@pytest.mark.parametrize("verb", [("slaves",), ("pdos",), ("sdo", "upload", "0", "0x1018", "1")])
def test_cli_without_any_eni_says_where_it_looked_and_how_to_give_one(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, verb: tuple[str, ...]
) -> None:
    monkeypatch.chdir(tmp_path)
    err = _one_line_error(*cli(*verb))
    assert f"no ENI file at {tmp_path / 'Gecat.eni'}" in err
    assert "--eni" in err and "GTECAT_ENI" in err


def test_gt_without_any_eni_returns_minus_9_with_the_remedy(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    assert gt.GT_Open(log="") == 0
    assert gt.GT_InitEcatComm() == -9  # entry 79: no ENI
    text = _last_error_line()
    assert "Gecat.eni" in text and "GTECAT_ENI" in text


# --- wrong path ---------------------------------------------------------------------------------
def test_cli_wrong_eni_path_names_the_absolute_path(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    err = _one_line_error(*cli("slaves", "--eni", "confg/Gecat.eni"))
    assert str(tmp_path / "confg" / "Gecat.eni") in err
    err = _one_line_error(*cli("map", "confg/Gecat.eni"))
    assert "confg/Gecat.eni" in err and "No such file" in err


def test_cli_wrong_machine_path(cli: Cli, tmp_path: Path) -> None:
    err = _one_line_error(*cli("slaves", "--eni", FIG52, "--machine", "nope.toml"))
    assert "nope.toml" in err and "not found" in err and "--machine" in err
    script = tmp_path / "s.py"
    script.write_text("print('ran')\n")
    err = _one_line_error(*cli("run", str(script), "--machine", "nope.toml"))
    assert err == "error: machine description nope.toml not found (--machine)\n"


def test_gt_wrong_machine_path_returns_7_at_gt_open() -> None:
    assert gt.GT_Open(eni=FIG52, machine="nope.toml", log="") == 7
    assert "nope.toml: machine description not found" in _last_error_line()


def test_cli_a_file_that_is_not_an_eni(cli: Cli, tmp_path: Path) -> None:
    bad = tmp_path / "Gecat.eni"
    bad.write_text("hello\n")
    err = _one_line_error(*cli("slaves", "--eni", str(bad)))
    assert "not an ENI" in err and "EtherCATConfig" in err


def test_gt_wrong_path_returns_minus_9(tmp_path: Path) -> None:
    assert gt.GT_Open(eni=str(tmp_path / "typo.eni"), log="") == 0
    assert gt.GT_InitEcatComm() == -9
    assert "typo.eni" in _last_error_line()


# --- slave mismatch -----------------------------------------------------------------------------
def test_cli_slave_mismatch_names_the_slave_and_the_remedy(
    cli: Cli, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("GTECAT_BUS", OTHER_BUS)  # the emulated hardware is another machine
    err = _one_line_error(*cli("slaves", "--eni", FIG52))
    assert "slave 2: ENI expects 'IO 2' product code" in err
    assert "export" in err and "cabling" in err
    assert err.count("export") == 1, err  # the remedy once, not twice


def test_gt_slave_mismatch_returns_minus_8_naming_the_slave() -> None:
    assert gt.GT_Open(eni=FIG52, bus=OTHER_BUS, log="") == 0
    assert gt.GT_InitEcatComm() == -8  # entry 79
    text = _last_error_line()
    assert "slave 2" in text and "product code" in text and "'IO 2'" in text


def test_gt_missing_slave_names_the_first_missing_one(tmp_path: Path) -> None:
    shutil.copy(EXAMPLES / "manual_fig5_4.eni", tmp_path / "one.eni")
    assert gt.GT_Open(eni=FIG52, bus=str(tmp_path / "one.eni"), log="") == 0
    assert gt.GT_InitEcatComm() == -8
    assert "slave 0" in _last_error_line()


# --- unmapped object ----------------------------------------------------------------------------
def test_gt_unmapped_object_returns_1_naming_the_object() -> None:
    bring_up()
    pe = c_long()
    assert gt.GT_GetEcatAxisPE(1, byref(pe)) == 1  # 60F4h is not in figure 5-2's mapping
    text = _last_error_line()
    assert "0x60F4:00" in text and "following error" in text and "not mapped" in text
    ai = c_short()
    assert gt.GT_GetEcatAxisAI(2, 1, byref(ai)) == 1
    assert "0x20F2:00" in _last_error_line()


def test_cli_unmapped_trace_signal(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    script = tmp_path / "s.py"
    script.write_text(
        "from gtecat import gt\ngt.GT_Open(log='')\nprint(gt.GT_InitEcatComm())\ngt.GT_Close()\n"
    )
    rc, _, err = cli("run", str(script), "--eni", FIG52, "--trace", "1:0x6061:0")
    assert rc == 1 and "slave 1 maps no 0x6061:00" in err and "gtecat map" in err
    assert err.count("\n") == 1


def test_cli_unknown_trace_entry(cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    script = tmp_path / "s.py"
    script.write_text("from gtecat import gt\ngt.GT_Open(log='')\ngt.GT_InitEcatComm()\n")
    rc, _, err = cli("run", str(script), "--eni", FIG52, "--trace", "2:0x7000:9")
    assert rc == 1 and "slave 2 maps no 0x7000:09" in err and err.count("\n") == 1


# --- axis not enabled ---------------------------------------------------------------------------
@pytest.mark.skipif(not hasattr(gt, "GT_StartEcatHoming"), reason="homing calls not landed")
def test_gt_homing_an_axis_that_is_not_enabled_says_call_gt_axison() -> None:
    bring_up()
    assert gt.GT_SetHomingMode(1, 6) == 0
    assert gt.GT_SetEcatHomingPrm(1, 3, 5000, 3000, 100000, 0, 0) == 0
    assert gt.GT_StartEcatHoming(1) == 1
    text = _last_error_line()
    assert "not servo-enabled" in text and "call GT_AxisOn first" in text


@pytest.mark.skipif(
    not all(hasattr(gt, n) for n in ("GT_PrfTrap", "GT_SetPos", "GT_SetVel", "GT_Update")),
    reason="Trap calls not landed",
)
def test_gt_moving_an_axis_that_is_not_enabled_is_refused_with_a_reason() -> None:
    bring_up()
    prm = gt.TTrapPrm()
    prm.acc, prm.dec = 0.5, 0.5
    assert gt.GT_PrfTrap(1) == 0
    assert gt.GT_SetTrapPrm(1, byref(prm)) == 0
    assert gt.GT_SetPos(1, 10000) == 0 and gt.GT_SetVel(1, 10) == 0
    assert gt.GT_Update(1) == 1
    text = _last_error_line()
    assert "axis 1" in text and "GT_AxisOn" in text


def test_gt_axis_that_does_not_exist() -> None:
    bring_up()
    assert gt.GT_AxisOn(5) == 7
    assert "axis 5 out of range 1..2" in _last_error_line()


# --- order of calls -----------------------------------------------------------------------------
def test_gt_calls_before_gt_open_and_before_the_bus_is_up() -> None:
    assert gt.GT_InitEcatComm() == -1
    assert "call GT_Open first" in _last_error_line()
    assert gt.GT_Open(eni=FIG52, log="") == 0
    assert gt.GT_GetEcatRawData(0, 2, (c_short * 1)()) == 1
    assert "call GT_InitEcatComm" in _last_error_line()
    assert gt.GT_AxisOn(1) == 7  # no axes before the bus is read
    assert "bus not initialised" in _last_error_line()


# --- last-error semantics -----------------------------------------------------------------------
def test_the_last_error_is_per_call_a_success_clears_it() -> None:
    """GTE_GetLastError speaks of the most recent GT call only, like its return code."""
    assert gt.GT_InitEcatComm() == -1
    assert gt.GTE_GetLastError().startswith("GT_InitEcatComm returned -1: ")
    assert gt.GTE_GetLastError() == gt.GTE_GetLastError()  # reading it is not a call
    assert gt.GT_Open(eni=FIG52, log="") == 0
    assert gt.GTE_GetLastError() == ""  # GT_Open succeeded: no old reason left over
    assert gt.GT_AxisOn(9) == 7
    assert gt.GTE_GetLastError().startswith("GT_AxisOn returned 7: axis 9")
    ms = c_long()
    assert gt.GT_GetClock(byref(ms)) == 0
    assert gt.GTE_GetLastError() == ""


def test_the_reason_is_said_once() -> None:
    """The text carries the function and code once; callers print it as it is."""
    assert gt.GT_Open(eni=FIG52, log="") == 0
    assert gt.GT_AxisOn(9) == 7
    text = gt.GTE_GetLastError()
    assert text.count("returned") == 1 and text.count("GT_AxisOn") == 1


# --- the cases a new user met outside the repository --------------------------------------------
def test_run_a_binary_or_broken_script_is_one_line(cli: Cli, tmp_path: Path) -> None:
    binary = tmp_path / "binary.py"
    binary.write_bytes(b"\x7fELF\x02\x01\x01\x00\x00\x00")
    err = _one_line_error(*cli("run", str(binary)))
    assert "is not a Python script" in err and "NUL bytes" in err
    broken = tmp_path / "broken.py"
    broken.write_text("print(1\n")
    err = _one_line_error(*cli("run", str(broken)))
    assert "is not valid Python" in err and "line 1" in err and "python3" in err


def test_trace_out_into_a_missing_folder_is_refused_before_the_run(
    cli: Cli, tmp_path: Path
) -> None:
    script = tmp_path / "s.py"
    script.write_text("print('ran')\n")
    err = _one_line_error(*cli("run", str(script), "--trace", "axis1.prf", "--trace-out",
                               str(tmp_path / "nope" / "x")))  # fmt: skip
    assert f"the folder {tmp_path / 'nope'} does not exist" in err  # and 'ran' never printed


def test_sdo_subindex_out_of_range_is_one_line(cli: Cli) -> None:
    err = _one_line_error(*cli("sdo", "upload", "0", "0x6041", "300", "--eni", FIG52))
    assert "SUB 300 out of range 0..0xFF" in err and "internal" not in err


def test_an_eni_that_is_a_folder(cli: Cli, tmp_path: Path) -> None:
    shutil.copy(EXAMPLES / "manual_fig5_4.eni", tmp_path / "bus.eni")
    err = _one_line_error(*cli("slaves", "--eni", str(tmp_path)))
    assert "is a folder, not an ENI file (it holds bus.eni)" in err
    assert f"--eni {tmp_path / 'bus.eni'}" in err
    err = _one_line_error(*cli("map", str(tmp_path)))
    assert "is a folder" in err
    script = tmp_path / "s.py"
    script.write_text("print('ran')\n")
    err = _one_line_error(*cli("run", str(script), "--eni", str(tmp_path)))
    assert "is a folder, not a file (--eni)" in err


def test_an_emulated_bus_without_slaves_does_not_speak_of_cabling(cli: Cli, tmp_path: Path) -> None:
    import re

    text = re.sub(r"<Slave>.*?</Slave>\s*", "", Path(FIG52).read_text(), flags=re.S)
    (tmp_path / "e.eni").write_text(text)  # `gtecat eni new` refuses to write one
    err = _one_line_error(*cli("slaves", "--eni", str(tmp_path / "e.eni")))
    assert "lists no slaves, so the emulated bus is empty" in err and "cabling" not in err


def test_serve_on_a_missing_interface_says_so_first(cli: Cli) -> None:
    err = _one_line_error(*cli("serve", "--eni", FIG52, "--iface", "gtecat-missing0"))
    assert "no network interface 'gtecat-missing0'" in err and "gtecat ifaces" in err


def test_debug_works_after_the_verb_too(cli: Cli, tmp_path: Path) -> None:
    with pytest.raises(Exception, match="no ENI file"):
        cli("slaves", "--eni", str(tmp_path / "x.eni"), "--debug")


def test_topology_and_machine_description_are_not_confused(cli: Cli, tmp_path: Path) -> None:
    topology = str(EXAMPLES / "manual_fig5_2.toml")
    machine = str(EXAMPLES / "homing_probe_machine.toml")
    err = _one_line_error(*cli("slaves", "--eni", FIG52, "--machine", topology))
    assert "is a topology ([[slave]] tables" in err and "not a machine description" in err
    script = tmp_path / "s.py"
    script.write_text("print('ran')\n")
    assert "is a topology" in _one_line_error(*cli("run", str(script), "--machine", topology))
    err = _one_line_error(*cli("eni", "new", machine, "-o", str(tmp_path / "x.eni")))
    assert "is a machine description ([axis.N] tables" in err and "not a topology" in err


# --- nothing on the bus, files in the way ------------------------------------------------------
def test_an_empty_topology_is_refused_with_what_to_write(cli: Cli, tmp_path: Path) -> None:
    (tmp_path / "empty.toml").write_text("cycle_time_us = 1000\n")
    err = _one_line_error(*cli("eni", "new", str(tmp_path / "empty.toml"), "-o", "x.eni"))
    assert "no slaves" in err and "[[slave]]" in err
    assert not (tmp_path / "x.eni").exists()


@pytest.mark.parametrize("verb", ["map", "cstruct", "graph"])
def test_an_eni_without_slaves_is_refused(cli: Cli, tmp_path: Path, verb: str) -> None:
    import re

    text = re.sub(r"<Slave>.*?</Slave>\s*", "", Path(FIG52).read_text(), flags=re.S)
    (tmp_path / "zero.eni").write_text(text)
    err = _one_line_error(*cli(verb, str(tmp_path / "zero.eni")))
    assert "describes no slaves" in err


def test_a_folder_or_a_file_in_the_way_reads_as_a_sentence(cli: Cli, tmp_path: Path) -> None:
    folder = tmp_path / "out"
    folder.mkdir()
    err = _one_line_error(*cli("cstruct", FIG52, "-o", str(folder)))
    assert f"{folder} is a folder; give a file name" in err and "Errno" not in err
    (tmp_path / "afile").write_text("")
    err = _one_line_error(*cli("example", "manual_fig5_2", "-o", str(tmp_path / "afile")))
    assert "is in the way: it already exists and is not a folder" in err and "Errno" not in err
