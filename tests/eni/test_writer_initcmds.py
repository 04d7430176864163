"""The register InitCmds the writer emits, against bytes worked out by hand (ETG.1000.4 Tables
57 and 59, ETG.2100), read back from the XML as a replaying master reads them.

The bus: a servo with a mailbox (outputs 0x6040, inputs 0x6041 + 0x6064), a 4-bit output
terminal and a 12-bit input terminal without mailbox, so one direction each."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import pytest

from gtecat.eni.model import Direction, Pdo, PdoEntry
from gtecat.eni.reader import parse_eni
from gtecat.eni.register_cmds import SmMap, fmmu_bytes
from gtecat.eni.topology import load_topology
from gtecat.eni.writer import write_eni

TOPOLOGY = """
cycle_time_us = 1000
[[slave]]
kind = "servo"
rx = ["0x6040:0:16"]
tx = ["0x6041:0:16", "0x6064:0:32"]
[[slave]]
kind = "io"
do = 4
di = 0
packing = "bits"
[[slave]]
kind = "io"
do = 0
di = 12
packing = "bits"
"""


@pytest.fixture(scope="module")
def text(tmp_path_factory: pytest.TempPathFactory) -> str:
    path = Path(tmp_path_factory.mktemp("bus")) / "bus.toml"
    path.write_text(TOPOLOGY, encoding="utf-8")
    return write_eni(load_topology(path))


@dataclass(frozen=True)
class Cmd:
    """One register InitCmd as the XML states it."""

    tr: tuple[str, ...]
    comment: str
    cmd: int
    adp: int
    ado: int
    data: str | None
    cnt: str | None
    validate: tuple[str | None, str | None, str | None]

    @property
    def key(self) -> tuple[str, int, int, int, str | None]:
        return (self.comment, self.cmd, self.adp, self.ado, self.data)


def _cmds(node: ET.Element | None) -> list[Cmd]:
    assert node is not None
    return [
        Cmd(
            tuple(t.text or "" for t in c.findall("Transition")),
            c.findtext("Comment") or "",
            int(c.findtext("Cmd") or 0),
            int(c.findtext("Adp") or 0),
            int(c.findtext("Ado") or 0),
            c.findtext("Data"),
            c.findtext("Cnt"),
            (
                c.findtext("Validate/Data"),
                c.findtext("Validate/DataMask"),
                c.findtext("Validate/Timeout"),
            ),
        )
        for c in node.findall("InitCmds/InitCmd")
    ]


def _slaves(text: str) -> list[ET.Element]:
    return ET.fromstring(text).findall("Config/Slave")


def _by(cmds: list[Cmd], tr: str) -> list[tuple[str, int, int, int, str | None]]:
    """(comment, cmd, adp, ado, data) of one transition, in document order."""
    return [c.key for c in cmds if tr in c.tr]


def test_slave_children_in_schema_order(text: str) -> None:
    """ETG.2100 ``SlaveType``: Info, ProcessData, Mailbox, InitCmds (then PreviousPort, DC)."""
    tags = [[c.tag for c in s] for s in _slaves(text)]
    assert tags == [
        ["Info", "ProcessData", "Mailbox", "InitCmds"],
        ["Info", "ProcessData", "InitCmds"],
        ["Info", "ProcessData", "InitCmds"],
    ]
    master = ET.fromstring(text).find("Config/Master")
    assert master is not None and [c.tag for c in master] == ["Info", "InitCmds"]


def test_init_cmd_element_order(text: str) -> None:
    """As TwinCAT writes them: Transition, BeforeSlave, Comment, Requires, Cmd, Adp, Ado,
    Data or DataLength, Cnt, Retries, Timeout, Validate."""
    order = [
        "Transition",
        "BeforeSlave",
        "Comment",
        "Requires",
        "Cmd",
        "Adp",
        "Ado",
        "Data",
        "DataLength",
        "Cnt",
        "Retries",
        "Timeout",
        "Validate",
    ]
    root = ET.fromstring(text)
    for c in root.iter("InitCmd"):
        if c.find("Ccs") is not None:
            continue  # a CoE InitCmd (Mailbox/CoE/InitCmds)
        seen = [order.index(e.tag) for e in c]
        assert seen == sorted(seen), [e.tag for e in c]
        v = c.find("Validate")
        if v is not None:
            assert [e.tag for e in v] in (["Data", "DataMask", "Timeout"], ["Data", "Timeout"])


def test_servo_ip_commands(text: str) -> None:
    ip = _by(_cmds(_slaves(text)[0]), "IP")
    assert ip == [
        ("set device state to INIT", 2, 0, 0x0120, "1100"),  # with error acknowledge
        ("check device state for INIT", 1, 0, 0x0130, "0000"),
        ("assign EEPROM to ECAT", 2, 0, 0x0500, "00"),
        ("check vendor id", 2, 0, 0x0502, "000108000000"),  # read SII word 0008h
        ("check vendor id", 1, 0, 0x0508, "00000000"),
        ("check product code", 2, 0, 0x0502, "00010a000000"),  # read SII word 000Ah
        ("check product code", 1, 0, 0x0508, "00000000"),
        ("set physical address", 2, 0, 0x0010, "e903"),  # 1001
        ("set sm 0 (mailbox out)", 5, 1001, 0x0800, "0010800026000100"),
        ("set sm 1 (mailbox in)", 5, 1001, 0x0808, "8010800022000100"),
        ("set device state to PREOP", 5, 1001, 0x0120, "1200"),
        ("check device state for PREOP", 4, 1001, 0x0130, "000000000000"),
    ]
    cmds = _cmds(_slaves(text)[0])
    checks = [c.validate for c in cmds if "IP" in c.tr and c.validate[0]]
    assert checks == [
        ("0100", "0f00", "3000"),
        ("43455447", None, "100"),  # "GTEC"
        ("01000100", None, "100"),
        ("020000000000", "1f0000000000", "3000"),  # PREOP and no error bit
    ]


def test_servo_ps_so_commands(text: str) -> None:
    cmds = _cmds(_slaves(text)[0])
    assert _by(cmds, "PS") == [
        ("set sm 2 (outputs)", 5, 1001, 0x0810, "0011020064000100"),  # 1100h, 2 bytes
        ("set sm 3 (inputs)", 5, 1001, 0x0818, "0014060020000100"),  # 1400h, 6 bytes
        # logical 10000000h, 2 bytes, bits 0..7, physical 1100h, write, active
        ("set fmmu 0 (outputs)", 5, 1001, 0x0600, "00000010020000070011000201000000"),
        # the input image starts at logical 10000800h (after the outputs, 800h aligned)
        ("set fmmu 1 (inputs)", 5, 1001, 0x0610, "00080010060000070014000101000000"),
        ("set device state to SAFEOP", 5, 1001, 0x0120, "0400"),
        ("check device state for SAFEOP", 4, 1001, 0x0130, "000000000000"),
    ]
    assert _by(cmds, "SO") == [
        ("set device state to OP", 5, 1001, 0x0120, "0800"),
        ("check device state for OP", 4, 1001, 0x0130, "000000000000"),
    ]
    assert all(c.cnt == "1" for c in cmds if {"IP", "PS", "SO"} & set(c.tr))


def test_back_to_init_requests_and_checks_init(text: str) -> None:
    for s, ack in zip(_slaves(text), ("11", "01", "01"), strict=True):
        cmds = _cmds(s)
        for tr in ("PI", "SI", "OI", "BI"):
            assert [(c[0], c[4]) for c in _by(cmds, tr)] == [
                ("set device state to INIT", ack + "00"),
                ("check device state for INIT", "0000"),
            ]
        check = next(c for c in cmds if "SI" in c.tr and c.cmd == 1)
        assert check.validate == ("0100", "0f00", "5000")  # a pending error is fine here


def test_terminals_one_direction_each_no_mailbox(text: str) -> None:
    out4, in12 = _slaves(text)[1:]
    ip = [c[0] for c in _by(_cmds(out4), "IP")]
    assert not any("mailbox" in c for c in ip)
    assert ("set physical address", 2, 0xFFFF, 0x0010, "ea03") in _by(_cmds(out4), "IP")
    assert _by(_cmds(out4), "PS")[:2] == [
        ("set sm 2 (outputs)", 5, 1002, 0x0810, "0011010064000100"),
        # logical byte 2, 1 byte, bits 0..3 (4 outputs)
        ("set fmmu 0 (outputs)", 5, 1002, 0x0600, "02000010010000030011000201000000"),
    ]
    assert ("set physical address", 2, 0xFFFE, 0x0010, "eb03") in _by(_cmds(in12), "IP")
    assert _by(_cmds(in12), "PS")[:2] == [
        ("set sm 3 (inputs)", 5, 1003, 0x0818, "0014020020000100"),
        # input image byte 6 (logical 10000806h), 2 bytes, bit 0 to bit 3 of the second, read
        ("set fmmu 0 (inputs)", 5, 1003, 0x0600, "06080010020000030014000101000000"),
    ]


def _cyclic(root: ET.Element) -> dict[int, tuple[int, int, int]]:
    """Cyclic commands by command number: (logical address, data length, Cnt)."""
    return {
        int(c.findtext("Cmd") or 0): (
            int(c.findtext("Addr") or 0),
            int(c.findtext("DataLength") or 0),
            int(c.findtext("Cnt") or 0),
        )
        for c in root.findall("Config/Cyclic/Frame/Cmd")
    }


def test_the_cyclic_frame_writes_outputs_and_reads_inputs_apart(text: str) -> None:
    """An LWR of the 3-byte output image (2 slaves take outputs) and an LRD of the 8-byte
    input image (2 slaves give inputs) at 800h further on: the images never share bytes."""
    assert _cyclic(ET.fromstring(text)) == {11: (0x10000000, 3, 2), 10: (0x10000800, 8, 2)}


def test_fmmus_address_the_cyclic_frame(text: str) -> None:
    """Every FMMU's logical start is its direction's cyclic command's address + BitStart/8."""
    root = ET.fromstring(text)
    cyclic = _cyclic(root)
    addr = {"outputs": cyclic[11][0], "inputs": cyclic[10][0]}
    for s in root.findall("Config/Slave"):
        starts = {
            kind: int(s.findtext(f"ProcessData/{tag}/BitStart") or 0)
            for kind, tag in (("outputs", "Send"), ("inputs", "Recv"))
            if s.find(f"ProcessData/{tag}") is not None
        }
        fmmus = {
            c.comment.split("(")[1].rstrip(")"): bytes.fromhex(c.data or "")
            for c in _cmds(s)
            if c.comment.startswith("set fmmu")
        }
        assert fmmus.keys() == starts.keys()
        for kind, data in fmmus.items():
            assert int.from_bytes(data[:4], "little") == addr[kind] + starts[kind] // 8
            assert data[6] == starts[kind] % 8


EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.parametrize("eni", sorted(p.name for p in EXAMPLES.glob("*.eni")))
def test_no_slave_reads_what_another_slave_wrote_into_the_frame(eni: str) -> None:
    """Write FMMUs and read FMMUs never share a logical byte across slaves.  One LRW over
    both zero-based images did: in full_servo.eni the IO terminal took bytes 17-18 of the
    servo's inputs as its outputs (an outside check of the replay)."""
    written: dict[int, str] = {}
    read: dict[int, str] = {}
    for s in ET.parse(EXAMPLES / eni).getroot().findall("Config/Slave"):
        name = s.findtext("Info/Name") or ""
        for c in _cmds(s):
            if c.comment.startswith("set fmmu"):
                data = bytes.fromhex(c.data or "")
                start, length, kind = int.from_bytes(data[:4], "little"), data[4], data[11]
                for byte in range(start, start + length):
                    (written if kind == 2 else read)[byte] = name
    shared = {b: (written[b], read[b]) for b in written.keys() & read.keys()}
    assert all(w == r for w, r in shared.values()), shared


def test_master_before_slave_commands(text: str) -> None:
    root = ET.fromstring(text)
    cmds = _cmds(root.find("Config/Master"))
    assert [(c.comment, c.cmd, c.ado, c.cnt) for c in cmds] == [
        ("read slave count", 7, 0x0130, "3"),
        ("clear fmmu", 8, 0x0600, None),
        ("clear sm", 8, 0x0800, None),
    ]
    master = root.findall("Config/Master/InitCmds/InitCmd")
    assert [c.findtext("BeforeSlave") for c in master] == ["true"] * 3
    assert [c.findtext("DataLength") for c in master] == [None, "256", "256"]
    assert not any(
        c.find("BeforeSlave") is not None for c in root.iter("InitCmd") if c not in master
    )


def test_unaligned_fmmu_spans_two_bytes() -> None:
    """4 bits from logical bit 21: bytes 2 and 3, start bit 5, stop bit 0."""
    m = SmMap(2, Direction.OUT, (Pdo(0x1600, Direction.OUT, (PdoEntry(0x7000, 1, 4),)),), 21)
    assert fmmu_bytes(m).hex() == "02000010020005000011000201000000"


def test_the_reader_ignores_them(text: str) -> None:
    cfg = parse_eni(text, "bus.eni")
    assert [s.name for s in cfg.slaves] == ["servo 0", "io 1", "io 2"]
    assert write_eni(cfg) == text
