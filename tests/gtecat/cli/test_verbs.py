"""The IgH-style verbs on the emulated figure 5-2 bus: sdos, states, reg, sii, data, cstruct,
graph, ifaces; each with -p and --json where it applies, one-line errors otherwise."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from gtecat.eni.layout import build_layout
from gtecat.eni.reader import read_eni
from tests.conftest import EXAMPLES, SHARED_FIXTURES

from .conftest import Cli

FIG52 = str(EXAMPLES / "manual_fig5_2.eni")


def one_line_error(rc: int, out: str, err: str) -> str:
    assert rc == 1 and out == "" and err.startswith("error: ") and err.count("\n") == 1, err
    return err


# --- sdos ------------------------------------------------------------------------------------
def test_sdos_lists_the_dictionary_with_values(cli: Cli) -> None:
    rc, out, err = cli("sdos", "-p", "0", "--eni", FIG52)
    assert rc == 0 and err == ""
    head, *lines = out.splitlines()
    assert head.split() == ["pos", "index:sub", "type", "access", "pdo", "name", "value"]
    sw = next(line for line in lines if "0x6041:00" in line)
    assert sw.split()[:5] == ["0", "0x6041:00", "UINT16", "RO", "TxPDO"]
    assert sw.endswith("1616 (0x0650)") and "Statusword" in sw
    assert any("0x1018:01" in line and "Identity: Vendor ID" in line for line in lines)
    assert any("0x1008:00" in line and "'GTHD 0'" in line for line in lines)


def test_sdos_json_and_grep(cli: Cli) -> None:
    rc, out, _ = cli("sdos", "--eni", FIG52, "--grep", "homing method", "--json")
    rows = json.loads(out)
    assert rc == 0 and [(r["position"], r["index"]) for r in rows] == [(0, 0x6098), (1, 0x6098)]
    assert rows[0] | {"value": None, "hex": None} == {
        "position": 0, "index": 0x6098, "subindex": 0, "name": "Homing method", "type": "INT8",
        "bits": 8, "access": "RW", "pdo": "RxPDO", "value": None, "hex": None,
    }  # fmt: skip


def test_sdos_of_an_io_slave_without_coe_is_one_line(cli: Cli) -> None:
    err = one_line_error(*cli("sdos", "-p", "2", "--eni", FIG52))
    assert "slave 2 (IO 2) has no CoE object dictionary" in err


# --- states ----------------------------------------------------------------------------------
def test_states_shows_and_requests(cli: Cli) -> None:
    rc, out, _ = cli("states", "--eni", FIG52, "--json")
    assert rc == 0 and [r["state"] for r in json.loads(out)] == ["OP"] * 4
    rc, out, _ = cli("states", "-p", "1", "preop", "--eni", FIG52)
    assert rc == 0
    assert out.splitlines()[1].split()[:3] == ["1", "OP", "PREOP"]


def test_states_refuses_an_unknown_state(cli: Cli) -> None:
    err = one_line_error(*cli("states", "RUN", "--eni", FIG52))
    assert "no AL state 'RUN'" in err and "PREOP" in err


# --- reg -------------------------------------------------------------------------------------
def test_reg_read_al_status_and_write_al_control(cli: Cli) -> None:
    rc, out, _ = cli("reg", "read", "-p", "0", "0x0130", "--eni", FIG52)
    assert rc == 0 and out == "  0  0x0130  08 00  = 8 (0x0008)  AL_STATUS\n"  # OP
    rc, out, _ = cli("reg", "read", "0x0000", "1", "--eni", FIG52, "--json")
    assert [r["value"] for r in json.loads(out)] == [0x11] * 4  # ESC type
    rc, out, _ = cli("reg", "write", "-p", "0", "0x0120", "2", "--eni", FIG52)
    assert rc == 0 and "AL_CONTROL" in out


@pytest.mark.parametrize(
    ("argv", "text"),
    [
        (("read", "0x1zz"), "ADDRESS '0x1zz' is not a number"),
        (("read", "0x10000"), "out of range"),
        (("write", "0x0120", "2"), "needs -p POSITION"),
        (("write", "-p", "0", "0x0120"), "needs VALUE"),
        (("read", "-p", "9", "0x0130"), "no slave 9: the bus has slaves 0..3"),
    ],
)
def test_reg_errors(cli: Cli, argv: tuple[str, ...], text: str) -> None:
    assert text in one_line_error(*cli("reg", *argv, "--eni", FIG52))


# --- sii -------------------------------------------------------------------------------------
def test_sii_read_decodes_the_identity_and_pdos(cli: Cli, tmp_path: Path) -> None:
    rc, out, _ = cli("sii", "read", "-p", "0", "--eni", FIG52, "--json")
    (r,) = json.loads(out)
    assert rc == 0 and r["name"] == "GTHD 0" and r["product_code"] == 0x00010001
    assert "COE" in r["mailbox_protocols"]
    assert [(p["dir"], p["index"]) for p in r["pdos"]] == [("out", 0x1600), ("in", 0x1A00)]
    rc, out, _ = cli("sii", "read", "-p", "0", "--eni", FIG52)
    assert out.startswith("slave 0: GTHD 0\n") and '0x6041:00, 16 bit, "Statusword"' in out
    rc, out, _ = cli("sii", "read", "-p", "2", "--raw", "--eni", FIG52)
    assert rc == 0 and out.splitlines()[1].startswith("  0000  ")
    assert (
        cli("sii", "read", "-p", "1", "--output", str(tmp_path / "s.sii"), "--eni", FIG52)[0] == 0
    )
    assert (tmp_path / "s.sii").stat().st_size == r["bytes"]


# --- data ------------------------------------------------------------------------------------
def test_data_dumps_the_gt_raw_image(cli: Cli) -> None:
    rc, out, _ = cli("data", "--eni", FIG52)
    assert rc == 0 and out.splitlines()[0] == "slave 0  GTHD 0  GT raw 0+16"
    assert out.splitlines()[1] == "      0  00 00 00 00 00 00 50 06 00 00 00 00 00 00 00 00"
    rc, out, _ = cli("data", "-p", "1", "--entries", "--eni", FIG52)
    assert any(
        line.split()[:5] == ["in", "0x6041:00", "22.0", "1616", "0x0650"]
        for line in out.splitlines()
    )
    rc, out, _ = cli("data", "-p", "0", "--json", "--eni", FIG52)
    (s,) = json.loads(out)
    assert s["bytes"][12:16] == "5006" and s["gt_size"] == 16


# --- cstruct ---------------------------------------------------------------------------------
ENIS = [EXAMPLES / f for f in ("manual_fig5_2.eni", "manual_fig5_4.eni", "twelve_axes.eni",
                               "full_servo.eni", "homing_probe.eni")]  # fmt: skip
if SHARED_FIXTURES.is_dir():
    ENIS += sorted(SHARED_FIXTURES.glob("*/*.eni")) + sorted(SHARED_FIXTURES.glob("*/*.xml"))


def test_cstruct_macros_are_the_map_offsets(cli: Cli) -> None:
    rc, out, _ = cli("cstruct", FIG52)
    assert rc == 0
    assert "#define GT_RAW_BYTES 40\n" in out
    assert "#define SLAVE1_STATUSWORD_6041_00 22 " in out  # manual 5.2.2.4
    assert "#define SLAVE2_GT_OFFSET 32\n" in out and "#define SLAVE3_GT_OFFSET 36\n" in out
    assert "#define SLAVE2_DI_BYTE_0_6000_01_REGION 2\n" in out  # GT_EcatIOReadInput offset


@pytest.mark.skipif(shutil.which("gcc") is None, reason="no C compiler")
@pytest.mark.parametrize("eni", ENIS, ids=[p.name for p in ENIS])
@pytest.mark.sample(2)
def test_cstruct_compiles_as_c_and_cpp_and_agrees_with_the_layout(
    cli: Cli, tmp_path: Path, eni: Path
) -> None:
    header = tmp_path / "gt_raw.h"
    rc, out, _ = cli("cstruct", str(eni), "-o", str(header))
    assert rc == 0 and out.startswith(f"wrote {header}")
    layout = build_layout(read_eni(eni))
    checks = [
        f'printf("%d %d\\n", (int)SLAVE{s.position}_GT_OFFSET, (int)SLAVE{s.position}_GT_SIZE);'
        for s in layout.slaves
    ]
    (tmp_path / "t.c").write_text(
        '#include <stdio.h>\n#include "gt_raw.h"\nint main(void) {\n'
        + "\n".join(checks)
        + '\nprintf("%d\\n", (int)GT_RAW_BYTES);\nreturn 0;\n}\n'
    )
    for cmd in (["gcc", "-std=c11"], ["g++", "-std=c++11", "-x", "c++"]):
        if shutil.which(cmd[0]) is None:
            continue
        build = subprocess.run(
            [*cmd, "-Wall", "-Wextra", "-Werror", str(tmp_path / "t.c"), "-o", str(tmp_path / "t")],
            capture_output=True, text=True,
        )  # fmt: skip
        assert build.returncode == 0, build.stderr  # the header's static asserts hold too
        run = subprocess.run([str(tmp_path / "t")], capture_output=True, text=True, check=True)
        want = [f"{s.gt_offset} {s.gt_size}" for s in layout.slaves] + [str(layout.gt_raw_bytes)]
        assert run.stdout.split("\n")[:-1] == want


# --- graph -----------------------------------------------------------------------------------
def test_graph_is_dot_in_bus_order(cli: Cli) -> None:
    rc, out, _ = cli("graph", FIG52)
    assert rc == 0 and out.startswith("digraph bus {") and out.rstrip().endswith("}")
    edges = [line.split("[")[0].strip() for line in out.splitlines() if "->" in line]
    assert edges == ["master -> slave0", "slave0 -> slave1", "slave1 -> slave2", "slave2 -> slave3"]
    assert "axis 1; GT raw 0+16" in out and "IO; GT raw 36+4" in out


def test_graph_png_without_dot_is_one_line(cli: Cli, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv("PATH", str(tmp_path))
    err = one_line_error(*cli("graph", FIG52, "--png", str(tmp_path / "b.png")))
    assert "Graphviz" in err


# --- ifaces ----------------------------------------------------------------------------------
def test_ifaces_lists_loopback(cli: Cli) -> None:
    if not Path("/sys/class/net/lo").exists():
        pytest.skip("no /sys/class/net")
    rc, out, _ = cli("ifaces", "--json")
    rows = json.loads(out)
    assert rc == 0 and any(r["name"] == "lo" and r["loopback"] for r in rows)
    rc, out, _ = cli("ifaces")
    assert out.splitlines()[0].split()[:3] == ["iface", "state", "mac"]


# --- every verb ------------------------------------------------------------------------------
VERBS = ["slaves", "pdos", "sdo", "sdos", "states", "reg", "sii", "data", "cstruct", "graph",
         "ifaces", "example", "map", "run", "serve", "eni", "api", "scan"]  # fmt: skip


@pytest.mark.parametrize("verb", VERBS)
def test_help_has_examples_and_no_internal_markup(
    verb: str, capsys: pytest.CaptureFixture[str]
) -> None:
    from gtecat.cli.main import main

    with pytest.raises(SystemExit):
        main([verb, "--help"])
    text = capsys.readouterr().out
    assert "example" in text.lower(), verb
    for bad in ("``", ":func:", ":mod:", ":class:", "DESIGN.md", "issue "):
        assert bad not in text, (verb, bad)


@pytest.mark.parametrize("verb", ["slaves", "pdos", "sdos", "states", "data", "sii"])
def test_p_out_of_range_is_one_line(cli: Cli, verb: str) -> None:
    argv = [verb, "read"] if verb == "sii" else [verb]
    err = one_line_error(*cli(*argv, "-p", "4", "--eni", FIG52))
    assert "no slave 4: the bus has slaves 0..3" in err
