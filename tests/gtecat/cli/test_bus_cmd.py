"""``gtecat slaves | pdos | sdo`` on the emulated figure 5-2 bus (issue 8 deliver 3)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from tests.conftest import EXAMPLES

from .conftest import Cli

FIG52 = str(EXAMPLES / "manual_fig5_2.eni")


# --- slaves ----------------------------------------------------------------------------------
def test_slaves_json_is_a_list_with_one_object_per_slave(cli: Cli) -> None:
    rc, out, err = cli("slaves", "--eni", FIG52, "--json")
    assert rc == 0 and err == ""
    rows = json.loads(out)
    assert isinstance(rows, list) and len(rows) == 4
    assert [r["position"] for r in rows] == [0, 1, 2, 3]
    assert [r["state"] for r in rows] == ["OP"] * 4
    assert [r["axes"] for r in rows] == [[1], [2], [], []]
    assert [(r["gt_offset"], r["gt_size"]) for r in rows] == [(0, 16), (16, 16), (32, 4), (36, 4)]
    assert [r["name"] for r in rows] == ["GTHD 0", "GTHD 1", "IO 2", "IO 3"]
    for r in rows:
        assert set(r) >= {"position", "state", "name", "vendor_id", "product_code", "revision"}
        assert isinstance(r["vendor_id"], int) and r["vendor_id"] > 0


def test_slaves_table_has_a_row_per_slave(cli: Cli) -> None:
    rc, out, _ = cli("slaves", "--eni", FIG52)
    assert rc == 0
    lines = out.splitlines()
    assert lines[0].split()[:3] == ["pos", "state", "vendor"]
    assert len(lines) == 5
    assert lines[1].split()[0:2] == ["0", "OP"] and lines[1].rstrip().endswith("GTHD 0")
    assert "32+4" in lines[3] and lines[3].split()[5] == "-"  # IO 2: no axis


def test_slaves_finds_gecat_eni_in_the_working_directory_like_gt_open(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    shutil.copy(EXAMPLES / "manual_fig5_4.eni", tmp_path / "Gecat.eni")
    monkeypatch.chdir(tmp_path)
    rc, out, err = cli("slaves", "--json")
    assert rc == 0 and len(json.loads(out)) == 1, err
    monkeypatch.setenv("GTECAT_ENI", FIG52)
    rc, out, _ = cli("slaves", "--json")
    assert rc == 0 and len(json.loads(out)) == 4


# --- pdos ------------------------------------------------------------------------------------
def test_pdos_json_lists_the_assigned_pdos_and_entries(cli: Cli) -> None:
    rc, out, _ = cli("pdos", "--eni", FIG52, "--json")
    assert rc == 0
    slaves = json.loads(out)
    assert [s["position"] for s in slaves] == [0, 1, 2, 3]
    drive = slaves[0]["pdos"]
    assert [(p["dir"], p["index"]) for p in drive] == [("out", 0x1600), ("in", 0x1A00)]
    assert [(e["index"], e["bits"]) for e in drive[0]["entries"]] == [(0x6040, 16), (0x607A, 32)]
    assert [e["index"] for e in drive[1]["entries"]] == [0x6041, 0x6064, 0x60FD]


def test_pdos_table(cli: Cli) -> None:
    rc, out, _ = cli("pdos", "--eni", FIG52)
    assert rc == 0
    assert "=== slave 0: GTHD 0" in out
    assert "SM2: RxPDO 0x1600" in out and "SM3: TxPDO 0x1A00" in out
    assert '0x6041:00, 16 bit, UINT   "Statusword"' in out
    assert out.count("=== slave") == 4


# --- sdo -------------------------------------------------------------------------------------
def test_sdo_upload_typed_from_the_dictionary_with_hex_beside(cli: Cli) -> None:
    rc, out, _ = cli("sdo", "upload", "0", "0x1018", "1", "--eni", FIG52)
    _, js, _ = cli("slaves", "--eni", FIG52, "--json")
    vendor = json.loads(js)[0]["vendor_id"]  # 1018h:01 is the vendor id
    assert rc == 0 and out == f"{vendor}  (0x{vendor:08X}, uint32)\n"
    rc, out, _ = cli("sdo", "upload", "0", "0x1018", "1", "--type", "uint32", "--eni", FIG52)
    assert rc == 0 and out.split()[0] == str(vendor)
    # IgH's spelling: -p POSITION, and INDEX:SUB in one word
    assert cli("sdo", "upload", "-p", "0", "0x1018:01", "--eni", FIG52)[1] == out


def test_sdo_upload_by_name(cli: Cli) -> None:
    rc, out, _ = cli("sdo", "upload", "0", "Statusword", "--eni", FIG52)
    assert rc == 0 and out.endswith("(0x0650, uint16)\n")
    rc, out, _ = cli("sdo", "upload", "-p", "1", "vendor id", "--eni", FIG52)
    assert rc == 0 and out.startswith("1196705091 ")
    rc, out, err = cli("sdo", "upload", "0", "Identity", "--eni", FIG52)
    assert rc == 1 and "0x1018 with subindexes 0, 1, 2, 3, 4: give SUB" in err
    assert cli("sdo", "upload", "0", "Identity", "2", "--eni", FIG52)[1].startswith("65537 ")


def test_sdo_upload_json(cli: Cli) -> None:
    rc, out, _ = cli(
        "sdo", "upload", "1", "0x6041", "0", "--type", "uint16", "--json", "--eni", FIG52
    )
    assert rc == 0
    r = json.loads(out)
    assert (r["slave"], r["index"], r["subindex"]) == (1, 0x6041, 0)
    assert (r["name"], r["type"]) == ("Statusword", "UINT16")
    assert len(r["bytes"]) == 4 and r["value"] == int.from_bytes(
        bytes.fromhex(r["bytes"]), "little"
    )


def test_sdo_string_type_reads_the_device_name(cli: Cli) -> None:
    rc, out, _ = cli("sdo", "upload", "0", "0x1008", "0", "--eni", FIG52)
    assert rc == 0 and out == "GTHD 0\n"  # VISIBLE_STRING: the name the ENI gives the drive
    rc, typed, _ = cli("sdo", "upload", "0", "0x1008", "0", "--type", "string", "--eni", FIG52)
    assert typed == out
    rc, out, err = cli(
        "sdo", "download", "0", "0x1008", "0", "X", "--type", "string", "--eni", FIG52
    )
    assert (rc, out) == (1, "") and "0x06010002" in err  # the name is read-only: its abort


def test_sdo_download_takes_the_type_from_the_dictionary(cli: Cli) -> None:
    assert cli("sdo", "download", "0", "0x6060", "0", "6", "--eni", FIG52) == (0, "", "")
    rc, _, err = cli("sdo", "download", "0", "0x6060", "0", "300", "--eni", FIG52)
    assert rc == 1 and "does not fit int8" in err


def test_sdo_download_is_silent_on_success(cli: Cli) -> None:
    rc, out, err = cli("sdo", "download", "0", "0x6060", "0", "6", "--type", "int8", "--eni", FIG52)
    assert (rc, out, err) == (0, "", "")
    rc, out, _ = cli(
        "sdo", "download", "0", "0x607C", "0", "-1000", "--type", "int32", "--json", "--eni", FIG52
    )
    assert rc == 0 and json.loads(out) == {"ok": True}


@pytest.mark.parametrize(
    ("argv", "code", "text"),
    [
        (("download", "0", "0x6041", "0", "6", "--type", "uint16"), "0x06010002", "read-only"),
        (("upload", "0", "0x2FFF", "0"), "0x06020000", "does not exist"),
        (("upload", "0", "0x1018", "9"), "0x06090011", "ubindex"),
    ],
)
def test_sdo_abort_prints_the_cia301_code_in_one_line(
    cli: Cli, argv: tuple[str, ...], code: str, text: str
) -> None:
    rc, out, err = cli("sdo", *argv, "--eni", FIG52)
    assert rc == 1 and out == ""
    assert err.count("\n") == 1 and err.startswith("error: ")
    assert code in err and text in err


@pytest.mark.parametrize(
    ("argv", "text"),
    [
        (("upload", "2", "0x1018", "1"), "has no CoE mailbox"),
        (("upload", "7", "0x1018", "1"), "no slave 7: the bus has slaves 0..3"),
        (("download", "0", "0x6060", "0", "300", "--type", "int8"), "does not fit int8"),
        (("download", "0", "0x6060", "0"), "needs VALUE"),
        (("upload", "0", "0x60zz", "0"), "no object called '0x60zz'"),
        (("upload", "0", "0x6041", "300"), "SUB 300 out of range 0..0xFF"),
        (("upload", "0", "0x16041", "0"), "INDEX 0x16041 out of range 0..0xFFFF"),
        (("upload", "0", "0x6041", "0", "7"), "unexpected 7"),
        (("upload", "x", "0x6041", "0"), "give the slave first"),
        (("upload", "0", "0x6041", "0", "--type", "uint32"), "has 2 bytes, uint32 needs 4"),
        # a value that is not a number is the user's mistake, not an internal error
        (("download", "0", "0x6060", "0", "abc", "--type", "int8"), "VALUE 'abc' is not an int"),
        (("download", "0", "0x6060", "0", "1,5", "--type", "float"), "VALUE '1,5' is not a num"),
    ],
)
def test_sdo_bad_requests_are_one_clear_line(cli: Cli, argv: tuple[str, ...], text: str) -> None:
    rc, out, err = cli("sdo", *argv, "--eni", FIG52)
    assert rc == 1 and out == ""
    assert err.count("\n") == 1 and text in err and "Traceback" not in err
