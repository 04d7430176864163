"""Layout API: entry lookup, axes (16-bit controlword/statusword pairs), signedness, JSON."""

from __future__ import annotations

import json

from gtecat.eni.layout import build_layout
from gtecat.eni.model import Direction, EniConfig, Identity, Pdo, PdoEntry, ProcessDataArea, Slave

OUT, IN = Direction.OUT, Direction.IN


def _slave(pos: int, rx: list[PdoEntry], tx: list[PdoEntry], **kw: object) -> Slave:
    return Slave(
        pos,
        f"S{pos}",
        Identity(1, 2),
        rx_pdos=(Pdo(0x1600, OUT, tuple(rx)),) if rx else (),
        tx_pdos=(Pdo(0x1A00, IN, tuple(tx)),) if tx else (),
        **kw,
    )  # type: ignore[arg-type]


def _cfg(*slaves: Slave) -> EniConfig:
    return EniConfig("mem", "xml", tuple(slaves))


def test_axis_needs_16_bit_controlword_and_statusword() -> None:
    cw, sw = PdoEntry(0x6040, 0, 16), PdoEntry(0x6041, 0, 16)
    layout = build_layout(
        _cfg(
            _slave(0, [cw], [sw]),
            _slave(1, [PdoEntry(0x7040, 1, 1)], [PdoEntry(0x7041, 1, 1)]),  # ETG.5001 IO bits
            _slave(2, [cw], []),  # controlword only
            _slave(3, [PdoEntry(0x6040, 0, 8)], [sw]),  # wrong size
            _slave(
                4,
                [PdoEntry(0x6840, 0, 16), PdoEntry(0x7040, 0, 16)],
                [PdoEntry(0x6841, 0, 16), PdoEntry(0x7041, 0, 16)],
            ),  # channels 1 and 2
        )
    )
    assert [s.axes for s in layout.slaves] == [(1,), (), (), (), (2, 3)]
    assert layout.slaves[4].channels == (1, 2)
    assert layout.axis(3).channel == 2
    assert layout.axis_entry(3, 0x6041).index == 0x7041
    assert layout.axis_entry(4, 0x6041) is None and layout.axis(0) is None


def test_entry_lookup_and_direction() -> None:
    e = PdoEntry(0x2000, 1, 8)
    layout = build_layout(_cfg(_slave(0, [e], [e])))
    assert layout.entry(0, 0x2000, 1).direction == OUT
    assert layout.entry(0, 0x2000, 1, IN).gt_bit == 8
    assert layout.entry(0, 0x2000, 2) is None and layout.entry(5, 0x2000, 1) is None


def test_signed_from_type_else_cia402_object() -> None:
    rx = [
        PdoEntry(0x607A, 0, 32),
        PdoEntry(0x60FF, 0, 32),
        PdoEntry(0x6071, 0, 16),
        PdoEntry(0x6060, 0, 8),
        PdoEntry(0x6040, 0, 16),
        PdoEntry(0x60B8, 0, 16),
        PdoEntry(0x7000, 1, 16, data_type="INT"),
        PdoEntry(0x7000, 2, 16),
        PdoEntry(0x6860, 1, 8),
    ]
    tx = [
        PdoEntry(0x6064, 0, 32),
        PdoEntry(0x606C, 0, 32),
        PdoEntry(0x60F4, 0, 32),
        PdoEntry(0x6077, 0, 16),
        PdoEntry(0x6078, 0, 16),
        PdoEntry(0x60BA, 0, 32),
        PdoEntry(0x60BD, 0, 32),
        PdoEntry(0x6041, 0, 16),
        PdoEntry(0x60FD, 0, 32),
        PdoEntry(0x60B9, 0, 16),
        PdoEntry(0x6061, 0, 8),
        PdoEntry(0x6864, 0, 32),
    ]
    layout = build_layout(_cfg(_slave(0, rx, tx)))
    signed = {(p.index, p.subindex): p.signed for p in layout.slaves[0].entries}
    for idx in (
        0x607A,
        0x60FF,
        0x6071,
        0x6060,
        0x6064,
        0x606C,
        0x60F4,
        0x6077,
        0x6078,
        0x60BA,
        0x60BD,
        0x6061,
        0x6864,
    ):
        assert signed[(idx, 0)], hex(idx)
    for idx in (0x6040, 0x60B8, 0x6041, 0x60FD, 0x60B9):
        assert not signed[(idx, 0)], hex(idx)
    assert signed[(0x7000, 1)] and not signed[(0x7000, 2)]
    assert not signed[(0x6860, 1)]  # sub-index 1: an IO module object, not 6060 of channel 1
    assert layout.entry(0, 0x6864).name == "Position actual value"


def test_stated_offsets_win_and_regions_use_mapping_order() -> None:
    s = _slave(
        0,
        [PdoEntry(0x7000, 1, 8, logical_bit=800), PdoEntry(0x7000, 2, 8)],
        [],
        outputs=ProcessDataArea(800, 16),
    )
    layout = build_layout(_cfg(s))
    assert [p.logical_bit for p in layout.slaves[0].entries] == [800, 808]
    assert layout.outputs_bytes == 102  # covers every entry (816 bits)


def test_to_json_schema() -> None:
    s0 = _slave(
        0,
        [PdoEntry(0x6040, 0, 16), PdoEntry(0, 0, 8)],
        [PdoEntry(0x6041, 0, 16)],
        outputs=ProcessDataArea(0, 24),
        inputs=ProcessDataArea(0, 16),
    )
    s1 = _slave(1, [], [])
    doc = build_layout(_cfg(s0, s1)).to_json()
    json.dumps(doc)  # plain JSON types only
    assert set(doc) == {"slaves", "gt_raw_bytes", "outputs_bytes", "inputs_bytes"}
    assert doc["gt_raw_bytes"] == 5 and doc["outputs_bytes"] == 3 and doc["inputs_bytes"] == 2
    a, b = doc["slaves"]
    assert set(a) == {"position", "name", "axis", "axes", "gt_offset", "gt_size", "entries"}
    assert (a["axes"], b["axes"]) == ([1], [])
    assert (a["axis"], a["gt_offset"], a["gt_size"], b["axis"], b["gt_offset"]) == (
        1,
        0,
        5,
        None,
        5,
    )
    assert a["entries"] == [  # padding is not an object and is left out
        {
            "dir": "out",
            "index": 0x6040,
            "subindex": 0,
            "name": "Controlword",
            "bits": 16,
            "gt_bit": 0,
            "logical_bit": 0,
        },
        {
            "dir": "in",
            "index": 0x6041,
            "subindex": 0,
            "name": "Statusword",
            "bits": 16,
            "gt_bit": 24,
            "logical_bit": 0,
        },
    ]
