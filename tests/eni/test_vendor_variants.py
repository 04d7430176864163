"""Configuration files as vendors' tools write them, beyond the shared fixtures (outside check).

Each test pins a variant the issue-2 outside check met: its expected offsets are
computed by hand here from the DESIGN.md rule (manual 5.2.2.4: slaves in bus
order, each slave's RxPDO bytes then its TxPDO bytes), never by the code under test.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gtecat.eni.errors import EniError
from gtecat.eni.layout import build_layout
from gtecat.eni.model import Direction
from gtecat.eni.reader import parse_eni, read_eni

from .googol_text import GSlave, render
from .snippets import area, eni, entry, image, line_of, pdo, process_data, slave, variable

OUT, IN = Direction.OUT, Direction.IN
DATA = Path(__file__).resolve().parent / "data"


# --- Googol INI: the vendor's 4-axis module between a stepper and an IO slave ------------------
def test_googol_gnm401_module_offsets_and_axes() -> None:
    """``data/googol_gnm401_mix.eni``: the Googol tool's own layout (CRLF, a GNM_401 4-axis
    module with 7 RxPDO / 12 TxPDO objects per channel at +0x800*k, fixtures/README.md).

    Hand computation: slave 0 (DM3E) 8 out + 19 in = bytes 0..26; slave 1 channel k has
    19 out bytes (16+8+32+16+32+16+32 bits) and 37 in bytes (296 bits), so 6040+0x800k is
    at 27+19k, 6041+0x800k at 27+76+37k, 6064+0x800k three bytes later; slave 2 at 251.
    """
    cfg = read_eni(DATA / "googol_gnm401_mix.eni")
    layout = build_layout(cfg)
    assert [s.gt_offset for s in layout.slaves] == [0, 27, 251]
    assert [s.gt_size for s in layout.slaves] == [27, 224, 4]
    assert layout.gt_raw_bytes == 255
    assert (layout.outputs_bytes, layout.inputs_bytes) == (86, 169)
    assert layout.entry(0, 0x6041).gt_byte == 10
    for k in range(4):
        assert layout.entry(1, 0x6040 + 0x800 * k).gt_byte == 27 + 19 * k
        assert layout.entry(1, 0x6041 + 0x800 * k).gt_byte == 103 + 37 * k
        assert layout.entry(1, 0x6064 + 0x800 * k).gt_byte == 106 + 37 * k
    assert layout.entry(2, 0x7000, 2).gt_byte == 252 and layout.entry(2, 0x6000, 1).gt_byte == 253
    assert [(a.axis, a.slave, a.channel) for a in layout.axes] == [
        (1, 0, 0),
        (2, 1, 0),
        (3, 1, 1),
        (4, 1, 2),
        (5, 1, 3),
    ]
    doc = json.loads(json.dumps(layout.to_json()))
    assert [(s["axis"], s["axes"]) for s in doc["slaves"]] == [
        (1, [1]),
        (2, [2, 3, 4, 5]),
        (None, []),
    ]


def test_googol_utf16_file_is_read_not_emptied() -> None:
    """Windows "Unicode" (UTF-16 with BOM) used to decode as bytes and give a 0-slave bus."""
    text = (DATA / "googol_gnm401_mix.eni").read_bytes().decode("utf-8")
    cfg = parse_eni(text.encode("utf-16"), "u16.eni")
    assert [s.name for s in cfg.slaves] == ["DM3E_522_COE_", "GNM_401_EM", "RT133_1BL10_EA"]
    assert build_layout(cfg).gt_raw_bytes == 255


def test_googol_gbk_names() -> None:
    text = render(
        [GSlave("伺服驱动器", 0x705, 0x1, [[(0x6040, 0, 16)]], [[(0x6041, 0, 16)]], True, 1)]
    )
    assert parse_eni(text.encode("gbk"), "gbk.eni").slaves[0].name == "伺服驱动器"


def test_googol_without_any_slave_section_is_an_error() -> None:
    text = "[CommonInfo]\nParam0=name=version,Section=FLOAT,Value=0.020000\n\n[MasterInfo]\n"
    with pytest.raises(EniError, match="describes no bus") as info:
        parse_eni(text, "head.eni")
    assert info.value.file == "head.eni"
    # an explicit empty bus is consistent (GT_InitEcatComm then reports -10, no slaves)
    empty = text + "[SlaveIndex]\nParam0=name=slavenum,Section=DWORD,Value=0\n"
    assert parse_eni(empty, "empty.eni").slaves == ()


# --- ETG.2100 XML ---------------------------------------------------------------------------------
def _drive_with_esi_sm_attributes() -> str:
    """An Elmo-style drive: Sm2/Sm3 lists assign 0x1605+0x160B / 0x1A03, while the offered
    alternatives keep the ``Sm`` attribute the ESI gave them (tools copying ESI PDOs do)."""
    rx = (
        pdo("RxPdo", "#x1600", entry("#x6040", 0, 16) + entry("#x6060", 0, 8), "Alt", sm=2)
        + pdo("RxPdo", "#x1605", entry("#x607A", 0, 32) + entry("#x6060", 0, 8), "R6", sm=2)
        + pdo("RxPdo", "#x160B", entry("#x6040", 0, 16) + entry("#x60B8", 0, 16), "R12", sm=2)
    )
    tx = pdo("TxPdo", "#x1A00", entry("#x6064", 0, 32), "Alt", sm=3) + pdo(
        "TxPdo", "#x1A03", entry("#x6041", 0, 16) + entry("#x6064", 0, 32), "T4", sm=3
    )
    sms = (
        "<Sm2><Type>Outputs</Type><Pdo>5637</Pdo><Pdo>5643</Pdo></Sm2>\n"
        "<Sm3><Type>Inputs</Type><Pdo>6659</Pdo></Sm3>\n"
    )
    return process_data(area("Send", 0, 72) + area("Recv", 0, 48) + sms + rx + tx)


def test_sm_lists_decide_over_esi_sm_attributes() -> None:
    """ETG.2100 ProcessData/SmN/Pdo is the assignment (what goes to 0x1C12/0x1C13); an ``Sm``
    attribute on an unlisted alternative is the ESI's default SM, not an assignment."""
    cfg = parse_eni(eni(slave("Drive", _drive_with_esi_sm_attributes(), phys=1001)), "elmo.xml")
    s = cfg.slaves[0]
    assert [p.index for p in s.rx_pdos] == [0x1605, 0x160B]
    assert [p.index for p in s.tx_pdos] == [0x1A03]
    layout = build_layout(cfg)
    # outputs: 607A 0..3, 6060 4, 6040 5..6, 60B8 7..8 (9 bytes); inputs from 9
    assert layout.entry(0, 0x6040, 0, OUT).gt_byte == 5
    assert layout.entry(0, 0x6041, 0, IN).gt_byte == 9
    assert layout.entry(0, 0x6064, 0, IN).gt_byte == 11
    assert layout.gt_raw_bytes == 15 and len(layout.axes) == 1


def test_sm_attribute_alone_still_assigns() -> None:
    """Without SmN/Pdo lists the ``Sm`` attribute is the assignment (acontis, TwinCAT)."""
    rx = pdo("RxPdo", "#x1600", entry("#x7000", 1, 8), sm=2) + pdo(
        "RxPdo", "#x1601", entry("#x7001", 1, 8)
    )
    cfg = parse_eni(eni(slave("IO", process_data(area("Send", 0, 8) + rx))), "t.xml")
    assert [p.index for p in cfg.slaves[0].rx_pdos] == [0x1600]
    # a list on Sm2 does not silence an Sm attribute naming another, unlisted SM (Sm4)
    more = pdo("RxPdo", "#x1700", entry("#x7100", 1, 8), sm=4)
    sm2 = "<Sm2><Type>Outputs</Type><Pdo>#x1600</Pdo></Sm2>\n"
    body = process_data(area("Send", 0, 16) + sm2 + rx + more)
    cfg = parse_eni(eni(slave("IO", body)), "t.xml")
    assert [(p.index, p.sm) for p in cfg.slaves[0].rx_pdos] == [(0x1600, 2), (0x1700, 4)]


def test_named_padding_entry_is_still_padding() -> None:
    """A gap (Index 0) keeps no name, so map/JSON leave it out like the unnamed ones."""
    rx = pdo(
        "RxPdo",
        "#x1600",
        entry("#x7000", 1, 1, "Out 1", "BOOL")
        + entry("#x0", 0, 7, "__unused")
        + entry("#x7000", 2, 8, "Out 2", "USINT"),
        sm=2,
    )
    cfg = parse_eni(eni(slave("IO", process_data(area("Send", 0, 16) + rx))), "t.xml")
    assert cfg.slaves[0].rx_pdos[0].entries[1].name == ""
    doc = build_layout(cfg).to_json()
    assert [(e["index"], e["gt_bit"]) for e in doc["slaves"][0]["entries"]] == [
        (0x7000, 0),
        (0x7000, 8),
    ]


def _gb2312_eni(name: str) -> bytes:
    text = eni(
        slave(
            name,
            process_data(area("Send", 0, 8) + pdo("RxPdo", "#x1600", entry("#x7000", 1, 8), sm=2)),
        )
    )
    return text.replace('encoding="utf-8"', 'encoding="GB2312"').encode("gbk")


def test_gb2312_declared_xml_is_decoded() -> None:
    """Chinese tools declare ``encoding="GB2312"``; expat cannot decode multi-byte codecs."""
    cfg = parse_eni(_gb2312_eni("数字量输出模块"), "gb.xml")
    assert cfg.slaves[0].name == "数字量输出模块"


def test_unknown_or_wrong_declared_encoding_is_a_file_error() -> None:
    data = _gb2312_eni("IO").replace(b"GB2312", b"klingon")
    with pytest.raises(EniError, match="unknown encoding 'klingon'") as info:
        parse_eni(data, "k.xml")
    assert (info.value.file, info.value.line) == ("k.xml", 1)
    bad = _gb2312_eni("IO").replace(b"<Name>IO</Name>", b"<Name>\xff\xff</Name>")
    with pytest.raises(EniError, match="not valid GB2312") as info:
        parse_eni(bad, "g.xml")
    assert info.value.line == bad[: bad.index(b"\xff")].count(b"\n") + 1


def _namesakes(with_areas: bool) -> str:
    """Two drives both named "Drive"; the second one first in both images (bits 0..15)."""
    body = []
    for k, start in enumerate((16, 0)):
        rx = pdo("RxPdo", "#x1600", entry("#x6040", 0, 16, "Controlword", "UINT"), "Out", sm=2)
        tx = pdo("TxPdo", "#x1A00", entry("#x6041", 0, 16, "Statusword", "UINT"), "In", sm=3)
        areas = area("Send", start, 16) + area("Recv", start, 16) if with_areas else ""
        body.append(slave("Drive", process_data(areas + rx + tx), phys=1001 + k))
    # sorted by offset, as TwinCAT writes them
    outputs = "".join(variable("Drive.Out.Controlword", offs, 16) for offs in (0, 16))
    inputs = "".join(variable("Drive.In.Statusword", offs, 16) for offs in (0, 16))
    return eni("".join(body), image(inputs=inputs, outputs=outputs))


def test_namesakes_without_areas_are_refused_not_swapped() -> None:
    """Variables are found by name: two slaves of one name and no Send/Recv would silently
    get each other's logical offsets (the exchange then feeds one drive the other's data)."""
    text = _namesakes(with_areas=False)
    with pytest.raises(EniError, match="share the name 'Drive'") as info:
        parse_eni(text, "same.xml")
    assert info.value.slave == 0 and info.value.line == line_of(text, "Drive.Out.Controlword")
    layout = build_layout(parse_eni(_namesakes(with_areas=True), "same.xml"))
    assert [layout.entry(k, 0x6040).logical_bit for k in (0, 1)] == [16, 0]
    assert [layout.entry(k, 0x6040).gt_byte for k in (0, 1)] == [0, 4]
