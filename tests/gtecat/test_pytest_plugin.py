"""The pytest plugin (gtecat/pytest_plugin.py): registered as an entry point, fixtures that
open and close a lockstep controller, files in each test's tmp_path (never the working
directory), --gtecat-trace for failing tests, and pytest-xdist.

Each case runs pytest in a child process in an empty folder, as a user's project would.
"""

from __future__ import annotations

import importlib.metadata
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from tests.conftest import is_setting

TESTS = textwrap.dedent(
    """
    import pytest
    from ctypes import byref, c_double, c_long


    def prf(gt, axis):
        pos = c_double()
        assert gt.GT_GetPrfPos(axis, byref(pos)) == 0
        return pos.value


    def test_bus_is_up_in_lockstep(gtecat_bus):
        gt = gtecat_bus.gt
        assert gtecat_bus.ctl.clock.mode == "lockstep"
        t0 = gtecat_bus.now_ms()
        gtecat_bus.wait(5)
        assert gtecat_bus.now_ms() - t0 == 5
        assert gtecat_bus.axes() == 2 and gtecat_bus.path.is_dir()


    def test_field_side(gtecat_bus, gtecat_field):
        io = gtecat_field(2)
        assert gtecat_bus.gt.GT_EcatIOBitWriteOutput(2, 0, 3, 1) == 0
        gtecat_bus.wait(2)
        assert io.get_output_bit(3)


    def test_recorder(gtecat_bus, gtecat_recorder):
        gtecat_bus.wait(10)
        assert gtecat_recorder.n == 10 and "axis2.sw" in gtecat_recorder.names


    @pytest.mark.gtecat(eni="homing_probe", machine="homing_probe")
    def test_marker_with_example_names(gtecat_bus, gtecat_machine):
        assert gtecat_bus.eni.name == "homing_probe.eni"
        assert gtecat_machine.name == "homing_probe_machine.toml"
        pos = c_double()
        assert gtecat_bus.gt.GTE_GetMachinePos(1, byref(pos)) == 0 and pos.value == 80000


    def test_env_for_an_application_that_opens_itself(gtecat_env):
        from gtecat import gt
        assert gt.GT_Open() == 0
        assert gt.GT_InitEcatComm() == 0
        assert gt.GTE_Controller().clock.mode == "lockstep"
        # the application forgets GT_Close: the fixture closes it


    def test_fails_with_a_trace(gtecat_bus):
        gtecat_bus.axis_on(1)
        assert gtecat_bus.gt.GT_AxisOn(7) == 7
        gtecat_bus.wait(20)
        assert prf(gtecat_bus.gt, 1) == 1, "on purpose"
    """
)


def _pytest(folder: Path, *args: str) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if not is_setting(k)}
    env.pop("PYTHONPATH", None)
    return subprocess.run(
        [sys.executable, "-P", "-m", "pytest", "-p", "no:cacheprovider", "-q", *args],
        cwd=folder,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )


def user_files(folder: Path) -> list[str]:
    """What is in ``folder`` but hidden files and Python's own byte-code cache (written
    where PYTHONDONTWRITEBYTECODE is not set)."""
    return sorted(p.name for p in folder.iterdir() if p.name[0] != "." and p.name != "__pycache__")


@pytest.fixture
def project(tmp_path: Path) -> Path:
    folder = tmp_path / "project"
    folder.mkdir()
    (folder / "test_machine.py").write_text(TESTS)
    (folder / "pytest.ini").write_text("[pytest]\ngtecat_eni = manual_fig5_2\n")
    return folder


def test_the_plugin_is_an_entry_point() -> None:
    eps = importlib.metadata.entry_points(group="pytest11")
    assert any(e.value == "gtecat.pytest_plugin" for e in eps)


@pytest.mark.long
def test_ini_options_choose_the_bus_and_no_trace_without_the_option(project: Path) -> None:
    (project / "pytest.ini").write_text("[pytest]\ngtecat_eni = full_servo\n")
    (project / "test_ini.py").write_text(
        "def test_one_axis(gtecat_bus):\n    assert gtecat_bus.axes() == 1\n"
    )
    # one child for two checks: the ini option's bus, and a failure without --gtecat-trace
    done = _pytest(project, "test_ini.py", "test_machine.py", "-k", "one_axis or fails")
    out = done.stdout
    assert "1 passed" in out and "1 failed" in out, out + done.stderr
    assert "gtecat trace" not in out
    assert "GT_AxisOn returned 7" in out  # the reasons are always reported
    (project / "pytest.ini").write_text("[pytest]\ngtecat_eni = no_such_bus\n")
    done = _pytest(project, "test_ini.py")
    assert done.returncode != 0 and "neither a file nor a shipped example" in (
        done.stdout + done.stderr
    )


@pytest.mark.skipif(
    importlib.util.find_spec("xdist") is None, reason="pytest-xdist is not installed"
)
@pytest.mark.long
def test_fixtures_and_a_failing_test_with_its_trace_under_xdist(project: Path) -> None:
    """One child pytest on two workers (the tutorial's page 6 shows its tests run with
    ``-n 2``: this is that promise's test): the fixtures, a failure's report and trace, and
    each worker and test with its own files - nothing in the working directory but the
    traces the option collects."""
    done = _pytest(project, "-n", "2", "--gtecat-trace", "--gtecat-trace-dir", "traces")
    out = done.stdout
    assert "5 passed" in out and "1 failed" in out, out + done.stderr
    assert "test_fails_with_a_trace" in out and "on purpose" in out
    assert "gtecat: recent GT errors" in out and "GT_AxisOn returned 7: axis 7" in out
    assert "gtecat trace" in out and "gtecat-trace.png" in out and "master log:" in out
    traces = sorted(p.name for p in (project / "traces").iterdir())
    assert traces == [
        "test_machine.py_test_fails_with_a_trace.csv",
        "test_machine.py_test_fails_with_a_trace.png",
    ]
    csv = (project / "traces" / traces[0]).read_text().splitlines()
    assert csv[0].startswith("time_ms,axis1.prf,axis1.enc") and len(csv) > 20
    # nothing in the working directory but what the user put there
    assert user_files(project) == ["pytest.ini", "test_machine.py", "traces"]
