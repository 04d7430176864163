"""The manual's examples 5-1, 5-4 and 5-5 as shipped (examples/), each checked against what the
manual says it does.  (5-2 and 5-3: test_examples and the homing/probe tests; the C++ listing of
5-5 built with libgts: tests/gtecat/native/test_example_5_5.py.)"""

from __future__ import annotations

import importlib.util
import shutil
import sys

import pytest

from gtecat import gt
from tests.conftest import EXAMPLES


@pytest.fixture(autouse=True)
def _closed_controller():
    gt.GT_Close()
    yield
    gt.GT_Close()


def example(name: str):
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
        assert spec is not None and spec.loader is not None
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod
        spec.loader.exec_module(mod)
    return sys.modules[name]


def test_example_5_1_returns_early_until_the_bus_is_in_op():
    """5-1: ``IF iEcatSts <> 1 THEN RETURN``: the scans after GT_InitEcatComm stop there while
    the slaves go up to OP, then every scan goes on."""
    v = example("example_5_1_ecat_status").run(scans=60, clock="lockstep")
    assert v.rtn == 0 and v.iEcatSts == 1
    assert 0 < v.returned_early < 60
    assert v.returned_early + v.went_on == 60


def test_example_5_4_reads_and_writes_the_offsets_of_figure_5_5():
    """5-4 on the figure 5-4 coupler: DI16 at 14, AI at 16, 18 and 20..23, DO16 at 2, AO4 at
    4..11 of slave 0; what the field side set is what the program read, and back."""
    r = example("example_5_4_ecat_io").run(clock="lockstep")
    assert r["errors"] == []
    assert r["read"] == (0x0F0F, 0x0100, 0x0200, [0x0300, 0x0400])
    assert (r["do16"], r["ao4"]) == (0x00A5, [1000, 2000, 3000, 4000])


def test_example_5_5_loads_the_cfg_by_the_controllers_own_path(tmp_path, monkeypatch):
    """5-5: ``GT_LoadConfig("\\\\hard disk\\\\CPAC\\\\GTS800.cfg")`` - the file's place on the
    controller's disk - reads GTS800.cfg of the working folder, and the master log says so."""
    shutil.copy(EXAMPLES / "GTS800.cfg", tmp_path)
    monkeypatch.chdir(tmp_path)
    rtn, log = example("example_5_5_init").run()  # the auto clock: the listing polls
    assert rtn == 0
    assert "\\hard disk\\CPAC\\GTS800.cfg (a Windows path) does not exist here" in log[0]
    assert "GTS800.cfg: 28 sections read, applied to axes 1-2" in log[1]
