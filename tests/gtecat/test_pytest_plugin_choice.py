"""Which bus the pytest plugin's fixtures build (gtecat/pytest_plugin.py): the user's machine
first - ``gtecat_eni`` (marker, ini) > ``GTECAT_ENI`` > ``./Gecat.eni`` in the rootdir > an
error that says how to choose; a shipped example only when named - and the header line that
says which.  Each case runs pytest in-process (``pytester``) on a folder of its own."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

import gtecat
import gtecat.cli.example_cmd
import gtecat.gt  # loaded here, so the in-process runs never load numpy twice

pytest_plugins = ["pytester"]

ONE_AXIS = "def test_axes(gtecat_bus):\n    assert gtecat_bus.axes() == {n}\n"
SHIPPED = Path(gtecat.__file__).parent / "examples"


@pytest.fixture
def mine(pytester: pytest.Pytester, monkeypatch: pytest.MonkeyPatch) -> pytest.Pytester:
    for k in ("GTECAT_ENI", "GTECAT_MACHINE", "GTECAT_CONTROLLER", "GTECAT_BACKEND"):
        monkeypatch.delenv(k, raising=False)
    pytester.makeini("[pytest]\n")
    return pytester


def _run(p: pytest.Pytester) -> pytest.RunResult:
    return p.runpytest_inprocess("-p", "no:cacheprovider", "-p", "no:xdist")


def test_nothing_named_is_an_error_that_says_how_to_choose(mine: pytest.Pytester) -> None:
    mine.makepyfile(test_axes=ONE_AXIS.format(n=2))
    out = _run(mine)
    out.assert_outcomes(errors=1)
    text = out.stdout.str()
    assert "which bus should the tests run against" in text
    assert "gtecat_eni" in text and "GTECAT_ENI" in text and "Gecat.eni" in text
    assert "gtecat: bus: none chosen" in text


@pytest.mark.long
def test_gecat_eni_in_the_rootdir_then_the_environment_then_the_ini(
    mine: pytest.Pytester, monkeypatch: pytest.MonkeyPatch
) -> None:
    shutil.copy(SHIPPED / "full_servo.eni", mine.path / "Gecat.eni")  # one axis
    mine.makepyfile(test_axes=ONE_AXIS.format(n=1))
    out = _run(mine)
    out.assert_outcomes(passed=1)
    assert "Gecat.eni (Gecat.eni in the rootdir)" in out.stdout.str()

    monkeypatch.setenv("GTECAT_ENI", "manual_fig5_2")  # named: the shipped two-axis bus
    mine.makepyfile(test_axes=ONE_AXIS.format(n=2))
    out = _run(mine)
    out.assert_outcomes(passed=1)
    assert "gtecat: bus manual_fig5_2 (GTECAT_ENI)" in out.stdout.str()

    mine.makeini("[pytest]\ngtecat_eni = Gecat.eni\n")  # the ini option wins
    mine.makepyfile(test_axes=ONE_AXIS.format(n=1))
    out = _run(mine)
    out.assert_outcomes(passed=1)
    assert "(gtecat_eni in tox.ini)" in out.stdout.str()  # pytester's makeini writes tox.ini
