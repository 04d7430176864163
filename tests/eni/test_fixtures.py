"""Every real configuration file in ../shared/fixtures parses, with offsets checked by hand.

The expected numbers below were computed from the fixture files themselves
(``Send``/``Recv`` BitStart, ``ProcessImage`` BitOffs, PDO entry sizes) and the
GT raw rule of manual 5.2.2.4 (slaves in bus order, each slave's output bytes
then its input bytes), not by running the code.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from gtecat.eni.layout import build_layout
from gtecat.eni.model import Direction
from gtecat.eni.reader import read_eni

OUT, IN = Direction.OUT, Direction.IN


def _all_fixture_files(root: Path) -> list[Path]:
    return sorted(p for p in root.rglob("*") if p.is_file() and p.suffix in (".xml", ".eni"))


def test_every_fixture_parses_and_lays_out(shared_fixtures: Path) -> None:
    files = _all_fixture_files(shared_fixtures)
    assert len(files) >= 4
    for f in files:
        layout = build_layout(read_eni(f))
        assert layout.slaves, f
        # GT raw regions follow each other from 0 (manual 5.2.2.4)
        pos = 0
        for s in layout.slaves:
            assert s.gt_offset == pos
            pos += s.gt_size
        assert layout.gt_raw_bytes == pos


def test_acontis_zero_based_bits_and_complete_access(shared_fixtures: Path) -> None:
    cfg = read_eni(shared_fixtures / "eni" / "acontis_training_slaves.xml")
    assert cfg.format == "xml"
    assert cfg.cycle_time_ns == 1_000_000  # Cyclic/CycleTime 1000 us
    assert cfg.master_name == "Class-A Master"
    assert (cfg.outputs_bytes, cfg.inputs_bytes) == (29, 29)  # ProcessImage ByteSize
    s0, s1 = cfg.slaves
    assert s0.identity.vendor_id == 16724 and s0.identity.product_code == 257
    assert (s0.phys_addr, s1.phys_addr, s1.auto_inc_addr) == (1001, 1002, 65535)
    # Sm2 lists 0x1600, 0x1601 (decimal 5632/5633) -> mapping order
    assert [p.index for p in s0.rx_pdos] == [0x1600, 0x1601]
    assert [p.index for p in s0.tx_pdos] == [0x1A00, 0x1A01]
    assert s0.out_bits == 72 and s0.in_bits == 72
    assert s1.out_bits == 128 and s1.in_bits == 96
    # the 14-bit padding entry of Counter1
    pad = s1.rx_pdos[0].entries[3]
    assert pad.is_padding and pad.bit_len == 14 and pad.logical_bit is None
    # CoE InitCmds: clear 1C12/1C13, then complete-access download of the assignment
    cmds = s0.init_cmds
    assert [(c.index, c.subindex, c.complete_access) for c in cmds] == [
        (0x1C12, 0, False),
        (0x1C13, 0, False),
        (0x1C12, 0, True),
        (0x1C13, 0, True),
    ]
    assert cmds[2].data == bytes.fromhex("020000160116")
    assert all(c.transitions == ("PS",) and not c.upload for c in cmds)
    assert cmds[0].comment == "clear sm pdos (0x1C12)"

    layout = build_layout(cfg)
    assert layout.gt_raw_bytes == 9 + 9 + 16 + 12
    e = layout.entry(0, 0x7000, 8)
    assert (e.logical_bit, e.gt_bit, e.bits, e.data_type) == (7, 7, 1, "BOOL")
    e = layout.entry(0, 0x7001, 4)  # Reserved_4 at BitOffs 56
    assert (e.logical_bit, e.gt_bit, e.signed) == (56, 56, True)
    e = layout.entry(0, 0x6001, 1)  # Triangle: inputs follow slave 0's 9 output bytes
    assert (e.logical_bit, e.gt_bit) == (8, 72 + 8)
    assert layout.slaves[1].gt_offset == 18
    e = layout.entry(1, 0x7000, 5)  # MaximumValue after the 14-bit gap
    assert (e.logical_bit, e.gt_bit) == (104, 18 * 8 + 32)
    e = layout.entry(1, 0x6001, 2)
    assert (e.logical_bit, e.gt_bit) == (152, (18 + 16) * 8 + 80)
    assert layout.axes == ()


def test_twincat_frame_relative_and_bit_pdos_on_sm0(shared_fixtures: Path) -> None:
    cfg = read_eni(shared_fixtures / "eni" / "twincat_ek1100_el2008_el4002_el1809.xml")
    assert cfg.cycle_time_ns is None  # TwinCAT wrote no CycleTime
    assert (cfg.outputs_bytes, cfg.inputs_bytes) == (1536, 1536)
    ek, el2008, el4002, el1809 = cfg.slaves
    assert ek.rx_pdos == () and ek.tx_pdos == () and ek.outputs is None
    assert [p.sm for p in el2008.rx_pdos] == [0] * 8  # outputs on SM0, direction from RxPdo
    assert el2008.outputs.bit_start == 344 and el2008.outputs.bit_len == 8
    assert el1809.inputs.bit_start == 448 and len(el1809.tx_pdos) == 16
    assert el4002.rx_pdos[0].entries[0].data_type == "INT"
    # TwinCAT-only variables (WcState, InfoData) are kept but belong to no entry
    assert any(v.name == "Inputs.DevState" for v in cfg.variables)

    layout = build_layout(cfg)
    assert [(s.gt_offset, s.gt_size) for s in layout.slaves] == [(0, 0), (0, 1), (1, 4), (5, 2)]
    assert layout.gt_raw_bytes == 7
    e = layout.entry(1, 0x7070, 1)
    assert (e.logical_bit, e.gt_bit) == (351, 7)
    e = layout.entry(2, 0x7010, 0x11)  # logical order differs from bus order here
    assert (e.logical_bit, e.gt_bit) == (328, 8 + 16)
    e = layout.entry(3, 0x60F0, 1)
    assert (e.logical_bit, e.gt_bit) == (463, 5 * 8 + 15)
    # EL1809 maps 0x6040:01 (1 bit) as an input: ETG.5001 channel 4, not a CiA-402 axis
    assert layout.entry(3, 0x6040, 1).bits == 1
    assert layout.axes == ()


def test_googol_stepper(shared_fixtures: Path) -> None:
    cfg = read_eni(shared_fixtures / "googol" / "Gecat_DM3E_stepper.eni")
    assert cfg.format == "googol"
    (s,) = cfg.slaves
    assert s.name == "DM3E_522_COE_"
    assert (s.identity.vendor_id, s.identity.product_code) == (0x4321, 0x8300)
    assert s.servo_hint is True and s.nservo_hint == 1
    assert cfg.cycle_time_ns == 1_000_000  # slave_dc cycletime0
    assert [e.index for p in s.rx_pdos for e in p.entries] == [0x6040, 0x607A, 0x60B8]
    assert [e.index for p in s.tx_pdos for e in p.entries] == [
        0x603F,
        0x6041,
        0x6061,
        0x6064,
        0x60B9,
        0x60BA,
        0x60FD,
    ]
    (sdo,) = s.init_cmds
    assert (sdo.transitions, sdo.index, sdo.subindex, sdo.data) == (("PS",), 0x6060, 0, b"\x08")

    layout = build_layout(cfg)
    sl = layout.slaves[0]
    assert (sl.out_bytes, sl.in_bytes) == (8, 19)
    assert sl.axes == (1,)
    assert layout.axis_entry(1, 0x6041).gt_bit == (8 + 2) * 8
    assert layout.axis_entry(1, 0x6064).gt_bit == (8 + 5) * 8
    assert layout.axis_entry(1, 0x6064).signed is True  # no data type in the file: CiA-402
    assert layout.axis_entry(1, 0x6061).data_type == "SINT"
    assert layout.axis_entry(1, 0x60FD).gt_bit == (8 + 15) * 8


def test_googol_io(shared_fixtures: Path) -> None:
    cfg = read_eni(shared_fixtures / "googol" / "Gecat_IO.eni")
    (s,) = cfg.slaves
    assert s.servo_hint is False and s.init_cmds == ()
    layout = build_layout(cfg)
    got = [(p.direction, p.index, p.subindex, p.gt_bit // 8) for p in layout.slaves[0].entries]
    assert got == [(OUT, 0x7000, 1, 0), (OUT, 0x7000, 2, 1), (IN, 0x6000, 1, 2), (IN, 0x6000, 2, 3)]
    assert layout.axes == ()


@pytest.mark.parametrize(
    "name", ["acontis_training_slaves.xml", "twincat_ek1100_el2008_el4002_el1809.xml"]
)
def test_stated_offsets_are_kept(shared_fixtures: Path, name: str) -> None:
    """Every entry with a ProcessImage variable keeps that variable's offset."""
    cfg = read_eni(shared_fixtures / "eni" / name)
    layout = build_layout(cfg)
    by_name = {(v.direction, v.name): v.bit_offset for v in cfg.variables}
    checked = 0
    for s, sl in zip(cfg.slaves, layout.slaves, strict=True):
        for p in (*s.rx_pdos, *s.tx_pdos):
            for e in p.entries:
                key = (p.direction, f"{s.name}.{p.name}.{e.name}")
                if key in by_name:
                    placed = layout.entry(s.position, e.index, e.subindex, p.direction)
                    assert placed.logical_bit == by_name[key]
                    checked += 1
        assert sl.position == s.position
    assert checked > 10
