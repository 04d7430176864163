"""``gtecat slaves | pdos | sdo --controller ADDR``: the verbs read a running controller's
bus (issue 13 deliver 7) and show what they show for a bus of their own."""

from __future__ import annotations

import json

import pytest

from gtecat import gt
from gtecat.native.server import Server
from tests.conftest import EXAMPLES

from .conftest import Cli

FIG52 = str(EXAMPLES / "manual_fig5_2.eni")


@pytest.fixture
def address(tmp_path):
    """This process's gt session with the bus up, served as a controller."""
    assert gt.GT_Open(eni=FIG52, clock="lockstep", log="") == 0
    assert gt.GT_InitEcatComm() == 0 and gt.GTE_Wait(100) == 0
    addr = f"unix:{tmp_path}/ctl.sock"
    with Server(addr, wall_floor=False):
        yield addr
    gt.GT_Close()


def test_slaves_and_pdos_of_a_running_controller_are_the_rows_of_a_bus_of_its_own(
    cli: Cli, address: str
) -> None:
    for verb in ("slaves", "pdos"):
        rc, remote, err = cli(verb, "--controller", address, "--json")
        assert rc == 0, err
        assert json.loads(remote) == json.loads(cli(verb, "--eni", FIG52, "--json")[1])
        rc, table, _ = cli(verb, "--controller", address)
        assert rc == 0 and table == cli(verb, "--eni", FIG52)[1]
    rc, out, _ = cli("slaves", "-p", "2", "--controller", address, "--json")
    assert rc == 0 and [r["name"] for r in json.loads(out)] == ["IO 2"]


def test_sdo_through_a_controller_types_from_its_dictionary_and_downloads_last(
    cli: Cli, address: str
) -> None:
    argv = ("sdo", "upload", "0", "0x1018", "1")
    assert cli(*argv, "--controller", address) == cli(*argv, "--eni", FIG52)
    assert cli("sdo", "download", "0", "0x6060", "0", "6", "--controller", address)[0] == 0
    rc, out, _ = cli("sdo", "upload", "0", "0x6060:00", "--controller", address, "--json")
    r = json.loads(out)
    assert rc == 0 and r["value"] == 6 and r["name"]  # the download stayed: one bus


@pytest.mark.parametrize(
    ("argv", "text"),
    [
        (("sdo", "upload", "0", "Statusword"), "give the index"),
        (("sdo", "upload", "7", "0x1018", "1"), "no slave 7: the bus has slaves 0..3"),
        (("sdo", "upload", "0", "0x2FFF", "0"), "0x06020000"),
        (("slaves", "-p", "9"), "no slave 9"),
    ],
)
def test_controller_refusals_are_one_line(cli: Cli, address: str, argv, text) -> None:
    rc, out, err = cli(*argv, "--controller", address)
    assert rc == 1 and out == "" and err.count("\n") == 1 and text in err, err


def test_no_controller_at_the_address_is_one_line(cli: Cli, tmp_path) -> None:
    rc, _, err = cli("slaves", "--controller", f"unix:{tmp_path}/none.sock")
    assert rc == 1 and err.startswith("error: cannot reach the controller at unix:")
