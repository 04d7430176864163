"""The inspection verbs against a running ``gtecat controller`` process (``--controller ADDR``,
``GTECAT_CONTROLLER``): each prints what it prints for a bus of its own, table and --json."""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Iterator
from ctypes import byref, c_short
from pathlib import Path

import pytest

from gtecat import gt
from gtecat.native.server import wait_for
from tests.conftest import EXAMPLES, ROOT
from tests.gtecat.native.conftest import native_env

from .conftest import Cli

FIG52 = str(EXAMPLES / "manual_fig5_2.eni")


def _controller(address: str, cwd: Path) -> subprocess.Popen:
    """A lockstep ``gtecat controller`` on figure 5-2, its bus brought to OP by an attached
    session that then detaches (the controller stays; lockstep: no cycles run after)."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "gtecat", "controller", "--listen", address, "--eni", FIG52],
        # this tree's gtecat, whatever an installed one is
        env=native_env(GTECAT_CLOCK="lockstep", PYTHONPATH=str(ROOT)),
        cwd=cwd,
        stderr=subprocess.DEVNULL,
    )
    try:
        wait_for(address, 60)
        assert gt.GT_Open(controller=address) == 0, gt.GTE_GetLastError()
        assert gt.GT_InitEcatComm() == 0, gt.GTE_GetLastError()
        ready = c_short()
        for _ in range(200):
            assert gt.GTE_Wait(5) == 0
            if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
                break
        assert ready.value == 1
        assert gt.GT_Close() == 0
    except BaseException:
        gt.GT_Close()
        proc.kill()
        proc.wait()
        raise
    return proc


def _stop(proc: subprocess.Popen) -> None:
    proc.kill()
    proc.wait(30)


@pytest.fixture(scope="module")
def shared(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """One controller for the verbs that only read."""
    d = tmp_path_factory.mktemp("ctl")
    address = f"unix:{d}/ctl.sock"
    proc = _controller(address, d)
    yield address
    _stop(proc)


@pytest.fixture
def address(tmp_path: Path) -> Iterator[str]:
    """A controller of this test's own (for the verbs that change the bus)."""
    address = f"unix:{tmp_path}/ctl.sock"
    proc = _controller(address, tmp_path)
    yield address
    _stop(proc)


READS = [
    ("slaves",),
    ("slaves", "-p", "2"),
    ("pdos",),
    ("pdos", "-p", "0"),
    ("sdo", "upload", "0", "0x1018", "1"),
    ("sdo", "upload", "0", "0x1008:00"),
    ("sdo", "upload", "1", "Statusword"),
    ("sdo", "upload", "0", "Modes of operation display"),
    ("sdos",),
    ("sdos", "-p", "1", "--grep", "homing"),
    ("sdos", "-p", "0", "--no-values"),
    ("states",),
    ("states", "-p", "3"),
    ("reg", "read", "-p", "0", "0x0130"),
    ("reg", "read", "0x0000", "8"),
    ("sii", "read"),
    ("sii", "read", "-p", "2", "--raw"),
    ("data",),
    ("data", "-p", "1", "--entries"),
    ("cstruct",),
    ("cstruct", "-p", "2", "--prefix", "X_"),
    ("graph",),
]


@pytest.mark.parametrize("argv", READS, ids=[" ".join(a) for a in READS])
@pytest.mark.parametrize("fmt", ["table", "json"])
@pytest.mark.sample(4)
def test_a_verb_on_a_running_controller_prints_what_it_prints_for_a_bus_of_its_own(
    cli: Cli, shared: str, argv: tuple[str, ...], fmt: str
) -> None:
    if fmt == "json" and argv[0] in ("cstruct", "graph"):
        pytest.skip(f"{argv[0]} prints C / DOT text, no JSON")
    extra = ("--json",) if fmt == "json" else ()
    rc, remote, err = cli(*argv, *extra, "--controller", shared)
    assert rc == 0 and err == "", err
    rc, local, err = cli(*argv, *extra, "--eni", FIG52)
    assert rc == 0 and err == "", err
    if fmt == "json":
        assert json.loads(remote) == json.loads(local)
    assert remote == local


def test_gtecat_controller_in_the_environment_is_read_unless_a_file_is_named(
    cli: Cli, shared: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("GTECAT_CONTROLLER", shared)
    rc, out, err = cli("states", "--json")
    assert rc == 0 and [r["state"] for r in json.loads(out)] == ["OP"] * 4, err
    monkeypatch.setenv("GTECAT_CONTROLLER", "unix:/nonexistent/ctl.sock")
    assert cli("states", "--eni", FIG52)[0] == 0  # the file wins
    assert cli("states")[2].startswith("error: cannot reach the controller at unix:/nonexistent")


@pytest.mark.long
def test_changes_through_a_controller_stay_on_its_bus(cli: Cli, address: str) -> None:
    assert cli("sdo", "download", "0", "0x6060", "0", "6", "--controller", address)[0] == 0
    rc, out, _ = cli("sdo", "upload", "0", "Modes of operation", "--controller", address, "--json")
    r = json.loads(out)
    assert rc == 0 and r["value"] == 6 and r["index"] == 0x6060  # by name, and it stayed

    rc, out, err = cli("states", "-p", "3", "PREOP", "--controller", address, "--json")
    (row,) = json.loads(out)
    assert rc == 0 and (row["before"], row["state"]) == ("OP", "PREOP"), err
    rc, out, _ = cli("reg", "read", "-p", "3", "0x0130", "--controller", address, "--json")
    assert json.loads(out)[0]["value"] == 2  # AL status PREOP: the ESC follows the slave

    rc, out, _ = cli("reg", "write", "-p", "2", "0x0F10", "0x1234", "--controller", address)
    assert rc == 0, out
    rc, out, _ = cli("reg", "read", "-p", "2", "0x0F10", "--controller", address, "--json")
    assert json.loads(out)[0]["value"] == 0x1234  # the general purpose outputs kept it


@pytest.mark.parametrize(
    ("argv", "text"),
    [
        (("sdo", "upload", "0", "Nothing like this"), "slave 0 has no object called"),
        (("sdo", "upload", "2", "Statusword"), "emulated slave's dictionary only"),
        (("sdo", "upload", "7", "0x1018", "1"), "no slave 7: the bus has slaves 0..3"),
        (("sdo", "upload", "0", "0x2FFF", "0"), "0x06020000"),
        (("slaves", "-p", "9"), "no slave 9"),
        (("sdos", "-p", "2"), "slave 2 (IO 2) has no CoE object dictionary"),
        (("states", "RUN"), "no AL state 'RUN'"),
        (("reg", "read", "-p", "4", "0x0130"), "no slave 4: the bus has slaves 0..3"),
        (("sii", "read", "-p", "4"), "no slave 4"),
        (("data", "-p", "4"), "no slave 4"),
        (("cstruct", "-p", "4"), "no slave 4"),
    ],
)
@pytest.mark.sample(2)
def test_controller_refusals_are_one_line(cli: Cli, shared: str, argv, text) -> None:
    rc, out, err = cli(*argv, "--controller", shared)
    assert rc == 1 and out == "" and err.count("\n") == 1 and text in err, err


@pytest.mark.long
def test_no_controller_at_the_address_is_one_line(cli: Cli, tmp_path) -> None:
    for verb in (("slaves",), ("sdos",), ("graph",), ("cstruct",)):
        rc, _, err = cli(*verb, "--controller", f"unix:{tmp_path}/none.sock")
        assert rc == 1 and err.startswith("error: cannot reach the controller at unix:"), verb
