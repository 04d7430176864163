"""What real applications assume around GT_LoadConfig: the path they pass was the file's path on
the controller's Windows PC, and their own ``.cfg`` describes the switches of the machine they
were written for (``reverse=1``: normally closed).  Facts: the vendor's smart-home demo
(``smarthome_test.cfg``, loaded as ``"test.cfg"``), manual example 5-5
(``GT_LoadConfig("\\\\hard disk\\\\CPAC\\\\GTS800.cfg")``), field applications'
``"\\\\gugao-board\\\\gugao1\\\\test.cfg"`` and ``"D:\\\\cfg\\\\GTS800.cfg"``.
"""

from __future__ import annotations

import dataclasses
import shutil
from ctypes import byref, c_long

import pytest

from gtecat import gt
from gtecat.drives.machine import AxisMachine, MachineDescription, machine_from_dict
from tests.conftest import EXAMPLES

from .test_load_config import fixture

POS_LIM, NEG_LIM, MOVING = 1 << 5, 1 << 6, 1 << 10


def _card(machine: MachineDescription | None = None, axes: int = 4) -> None:
    m = machine or MachineDescription({n: _axis() for n in range(1, axes + 1)})
    assert gt.GT_Open(card=f"gts:{axes}", machine=m, clock="lockstep", log="") == 0
    assert gt.GT_Reset() == 0


def _axis() -> AxisMachine:
    return AxisMachine(negative_limit=-30000, positive_limit=30000, home_switch=((10000, 12000),))


def sts(axis: int) -> int:
    v = c_long()
    assert gt.GT_GetSts(axis, byref(v)) == 0
    return v.value


# --- Windows paths ----------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("passed", "on_disk"),
    [
        ("\\gugao-board\\gugao1\\test.cfg", "test.cfg"),
        ("D:\\cfg\\GTS800.cfg", "GTS800.cfg"),
        ("D:\\cfg\\GTS800.cfg", "gts800.cfg"),  # Windows names ignore case
        ("\\hard disk\\CPAC\\GTS800.cfg", "GTS800.cfg"),  # manual example 5-5
        ("/opt/machine/cfg/test.cfg", "test.cfg"),
    ],
)
def test_a_path_that_does_not_exist_is_found_by_name_in_the_working_folder(
    tmp_path, monkeypatch, passed, on_disk
):
    shutil.copy(EXAMPLES / "GTS800.cfg", tmp_path / on_disk)
    monkeypatch.chdir(tmp_path)
    _card()
    assert gt.GT_LoadConfig(passed) == 0, gt.GTE_GetLastError()
    lines = [line for line in gt.GTE_Controller().log.lines if "does not exist here" in line]
    assert len(lines) == 1 and passed in lines[0] and on_disk in lines[0]
    assert ("a Windows path" in lines[0]) == ("\\" in passed)


def test_a_path_found_nowhere_is_7_naming_both_places(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _card()
    assert gt.GT_LoadConfig("D:\\cfg\\GTS800.cfg") == 7
    reason = gt.GTE_GetLastError()
    assert "D:\\cfg\\GTS800.cfg" in reason and "'GTS800.cfg'" in reason and str(tmp_path) in reason


def test_an_existing_path_is_read_as_given(tmp_path, monkeypatch):
    (tmp_path / "sub").mkdir()
    shutil.copy(EXAMPLES / "GTS800.cfg", tmp_path / "sub" / "test.cfg")
    monkeypatch.chdir(tmp_path)
    _card()
    assert gt.GT_LoadConfig("sub/test.cfg") == 0
    assert not any("does not exist" in line for line in gt.GTE_Controller().log.lines)


# --- normally-closed switches --------------------------------------------------------------------
def _home_demo_cfg(tmp_path) -> str:
    """The vendor smart-home demo's own test.cfg: axis 1's limits wired to limitPositive1 /
    limitNegative1 with reverse=1, home1 and home2 reverse=1 (normally-closed switches)."""
    shutil.copy(fixture("smarthome_test.cfg"), tmp_path / "test.cfg")
    return str(tmp_path / "test.cfg")


def test_the_demo_cfg_with_normally_closed_switches_runs_as_on_its_machine(tmp_path):
    """No switch_wiring in the machine description: the switches are wired as the file
    expects, so nothing reads triggered off the switches and the limit still works."""
    _card()
    assert gt.GT_LoadConfig(_home_demo_cfg(tmp_path)) == 0, gt.GTE_GetLastError()
    assert gt.GT_ClrSts(1, 4) == 0
    gt.GTE_Wait(2)  # a few cycles: the limit inputs are sampled
    assert sts(1) & (POS_LIM | NEG_LIM) == 0
    pos, neg = c_long(), c_long()
    assert gt.GT_GetDi(gt.MC_LIMIT_POSITIVE, byref(pos)) == 0 and pos.value & 1 == 0
    assert gt.GT_GetDi(gt.MC_LIMIT_NEGATIVE, byref(neg)) == 0 and neg.value & 1 == 0
    raw = c_long()
    assert gt.GT_GetDiRaw(gt.MC_LIMIT_POSITIVE, byref(raw)) == 0 and raw.value & 1 == 1  # NC
    log = "\n".join(gt.GTE_Controller().log.lines)
    assert "limitPositive1 reverse=1 (a normally-closed switch)" in log
    # the positive limit at +30000 still stops a move toward it and latches bit 5
    assert gt.GT_AxisOn(1) == 0 and gt.GT_PrfTrap(1) == 0
    prm = gt.TTrapPrm(acc=1, dec=1, velStart=0, smoothTime=0)
    assert gt.GT_SetTrapPrm(1, byref(prm)) == 0
    assert gt.GT_SetPos(1, 40000) == 0 and gt.GT_SetVel(1, 50) == 0
    assert gt.GT_Update(1) == 0
    for _ in range(3000):
        gt.GTE_Wait(1)
        if not sts(1) & MOVING:
            break
    assert sts(1) & POS_LIM


def test_a_machine_that_says_normally_open_reads_the_demo_cfg_inverted(tmp_path):
    """The machine description wins: switch_wiring = "normally_open" against the file's
    reverse=1 is a file that does not fit the machine - axis 1's limits read triggered."""
    m = machine_from_dict(
        {
            "axis": {
                str(n): {
                    "negative_limit": -30000,
                    "positive_limit": 30000,
                    **({"switch_wiring": "normally_open"} if n == 1 else {}),
                }
                for n in range(1, 5)
            }
        }
    )
    _card(m)
    assert gt.GT_LoadConfig(_home_demo_cfg(tmp_path)) == 0
    assert gt.GT_ClrSts(1, 4) == 0
    gt.GTE_Wait(2)  # a few cycles: the limit inputs are sampled
    assert sts(1) & (POS_LIM | NEG_LIM) == POS_LIM | NEG_LIM
    assert sts(2) & (POS_LIM | NEG_LIM) == 0  # axis 2's limits are none in the file


def test_switch_wiring_is_checked():
    with pytest.raises(Exception, match="switch_wiring 'nc'"):
        machine_from_dict({"axis": {"1": {"switch_wiring": "nc"}}})
    assert dataclasses.replace(_axis(), switch_wiring="normally_closed").switch_wiring
