"""The shipped examples reproduce every offset of manual 5.2.2.4 and 5.2.2.5 (DESIGN.md list).

The examples are written from their topology files; the test also checks the
``.eni`` in the repository is exactly what ``gtecat eni new`` writes today.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from gtecat.eni.layout import build_layout
from gtecat.eni.model import Direction
from gtecat.eni.reader import read_eni
from gtecat.eni.topology import load_topology
from gtecat.eni.writer import write_eni

OUT, IN = Direction.OUT, Direction.IN
EXAMPLES = ("manual_fig5_2", "manual_fig5_4", "twelve_axes")


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_eni_is_written_from_its_topology(examples_dir: Path, name: str) -> None:
    eni_text = (examples_dir / f"{name}.eni").read_text(encoding="utf-8")
    assert write_eni(load_topology(examples_dir / f"{name}.toml")) == eni_text


def _byte(layout, slave: int, index: int, sub: int = 0) -> int:  # type: ignore[no-untyped-def]
    p = layout.entry(slave, index, sub)
    assert p is not None, hex(index)
    assert p.gt_bit % 8 == 0
    return p.gt_bit // 8


def test_manual_5_2_2_4_figure_5_2(examples_dir: Path) -> None:
    """Manual 5.2.2.4 (2)/(3): slave0 6040=0, 6041=6; slave1 6040=16, 6041=22;
    slave2 region 32 (GT_SetEcatRawData(32,2) DO, GT_GetEcatRawData(34,2) DI);
    slave3 region 36 (DO 36, DI 38)."""
    layout = build_layout(read_eni(examples_dir / "manual_fig5_2.eni"))
    assert _byte(layout, 0, 0x6040) == 0
    assert _byte(layout, 0, 0x6041) == 6
    assert _byte(layout, 1, 0x6040) == 16
    assert _byte(layout, 1, 0x6041) == 22
    assert layout.slaves[2].gt_offset == 32
    assert _byte(layout, 2, 0x7000, 1) == 32 and _byte(layout, 2, 0x6000, 1) == 34
    assert layout.slaves[3].gt_offset == 36
    assert _byte(layout, 3, 0x7000, 1) == 36 and _byte(layout, 3, 0x6000, 1) == 38
    assert layout.gt_raw_bytes == 40
    # the rest of figure 5-2's mapping, in mapping order
    assert _byte(layout, 0, 0x607A) == 2 and _byte(layout, 0, 0x6064) == 8
    assert _byte(layout, 0, 0x60FD) == 12
    assert [(a.axis, a.slave) for a in layout.axes] == [(1, 0), (2, 1)]
    assert layout.axis_entry(2, 0x6064).signed and not layout.axis_entry(2, 0x60FD).signed


def test_manual_5_2_2_5_figure_5_4(examples_dir: Path) -> None:
    """Manual 5.2.2.5 / figure 5-5: one coupler slave; 0x7010:01 at 2, 0x7030:01..04 at 4..11,
    0x6000:01 at 14, 0x6020:01..04 at 16..23 (offsets inside the slave)."""
    layout = build_layout(read_eni(examples_dir / "manual_fig5_4.eni"))
    (s,) = layout.slaves
    assert (s.gt_offset, s.out_bytes, s.in_bytes) == (0, 12, 12)
    assert _byte(layout, 0, 0xF700, 1) == 0  # coupler word (outputs)
    assert _byte(layout, 0, 0x7010, 1) == 2  # GT_EcatIOWriteOutput(.., 0, 2, 2, DO16)
    assert [_byte(layout, 0, 0x7030, k) for k in (1, 2, 3, 4)] == [4, 6, 8, 10]
    assert _byte(layout, 0, 0xF600, 1) == 12  # coupler word (inputs)
    assert _byte(layout, 0, 0x6000, 1) == 14  # GT_EcatIOReadInput(.., 0, 14, 2, DI16)
    assert [_byte(layout, 0, 0x6020, k) for k in (1, 2, 3, 4)] == [16, 18, 20, 22]
    assert layout.entry(0, 0x6020, 4).bits == 16 and layout.entry(0, 0x6020, 4).signed
    assert layout.axes == ()


def test_twelve_axes(examples_dir: Path) -> None:
    layout = build_layout(read_eni(examples_dir / "twelve_axes.eni"))
    assert len(layout.axes) == 12
    assert [s.axes for s in layout.slaves] == [
        (1,),
        (2,),
        (3,),
        (4,),
        (5, 6, 7, 8),
        (9, 10, 11, 12),
        (),
        (),
    ]
    # single drive: 13 output bytes (16+8+32+16+32 bits), 17 input bytes
    assert [s.gt_offset for s in layout.slaves[:5]] == [0, 30, 60, 90, 120]
    # 4-axis module: channel k objects at +0x800*k, per-channel PDOs in order
    a7 = layout.axis_entry(7, 0x6041)  # module A channel 2
    assert a7.index == 0x7041 and a7.slave == 4
    assert a7.gt_bit == (120 + 52 + 2 * 17) * 8
    assert layout.axis_entry(12, 0x6040).index == 0x7840
    assert layout.axis_entry(12, 0x6040).gt_bit == (240 + 3 * 13) * 8
    assert layout.axis_entry(9, 0x6060).data_type == "SINT"
    # IO after the drives: DIO 16/16 then the coupler (DI16, DO16, AI2, AO2 + coupler words)
    assert layout.slaves[6].gt_offset == 360 and layout.slaves[6].gt_size == 4
    assert (layout.slaves[7].out_bytes, layout.slaves[7].in_bytes) == (8, 8)
    assert layout.gt_raw_bytes == 380
