"""Googol INI ``Gecat.eni``: multi-axis modules, several slaves, tolerant parsing, errors.

The GT raw order is the file's ``slave_iomap`` order: each slave's outputs then
its inputs (fixtures/README.md, manual 5.2.2.4).
"""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.eni.errors import EniError
from gtecat.eni.layout import build_layout
from gtecat.eni.model import Direction
from gtecat.eni.reader import parse_eni
from tests.conftest import examples

from .googol_text import GSlave, Noise, render
from .snippets import line_of

OUT, IN = Direction.OUT, Direction.IN

# a Googol-style 4-axis module: channel k at +0x800*k, one PDO per channel
_RX0 = [(0x6040, 0, 16), (0x6060, 0, 8), (0x607A, 0, 32)]
_TX0 = [(0x6041, 0, 16), (0x6061, 0, 8), (0x6064, 0, 32)]


def _ch(entries: list[tuple[int, int, int]], k: int) -> list[tuple[int, int, int]]:
    return [(i + 0x800 * k, s, b) for i, s, b in entries]


FOUR_AXIS = GSlave(
    "GNM 4-axis",
    0x705,
    0x4010,
    [_ch(_RX0, k) for k in range(4)],
    [_ch(_TX0, k) for k in range(4)],
    servo=True,
    nservo=4,
)
IO = GSlave(
    "IO 16/16",
    0x705,
    0x1111,
    [[(0x7000, 1, 8), (0x7000, 2, 8)]],
    [[(0x6000, 1, 8), (0x6000, 2, 8)]],
)
STEPPER = GSlave(
    "Stepper",
    0x4321,
    0x8300,
    [[(0x6040, 0, 16), (0x607A, 0, 32)]],
    [[(0x6041, 0, 16), (0x6064, 0, 32)]],
    servo=True,
    nservo=1,
    start_sdos=[(0x6060, 0, 1, 8), (0x6081, 0, 4, 0x12345678)],
)


def test_four_axis_module_then_io_then_stepper() -> None:
    cfg = parse_eni(render([FOUR_AXIS, IO, STEPPER]), "Gecat.eni")
    assert [s.name for s in cfg.slaves] == ["GNM 4-axis", "IO 16/16", "Stepper"]
    layout = build_layout(cfg)
    mod, io, step = layout.slaves
    assert (mod.out_bytes, mod.in_bytes) == (28, 28)
    assert mod.channels == (0, 1, 2, 3) and mod.axes == (1, 2, 3, 4)
    assert io.axes == () and step.axes == (5,)
    assert (io.gt_offset, step.gt_offset) == (56, 60)
    # channel 2 statusword 0x7041: inputs start at 28, channel k block is 7 bytes
    assert layout.axis_entry(3, 0x6041).index == 0x7041
    assert layout.axis_entry(3, 0x6041).gt_bit == (28 + 14) * 8
    assert layout.axis_entry(4, 0x607A).gt_bit == (21 + 3) * 8
    assert layout.axis_entry(5, 0x6064).gt_bit == (60 + 6 + 2) * 8
    # our logical layout: slaves in order, byte aligned, per direction
    assert step.out_logical_bit == (28 + 2) * 8 and step.in_logical_bit == (28 + 2) * 8
    assert (layout.outputs_bytes, layout.inputs_bytes) == (36, 36)
    sdo = cfg.slaves[2].init_cmds
    assert [(c.index, c.data) for c in sdo] == [
        (0x6060, b"\x08"),
        (0x6081, bytes.fromhex("78563412")),
    ]
    assert cfg.slaves[0].mailbox and not cfg.slaves[1].mailbox


def test_nservo_and_type_limit_the_axes() -> None:
    two = GSlave("2 of 4", 1, 2, FOUR_AXIS.rx, FOUR_AXIS.tx, servo=True, nservo=2)
    io_type = GSlave("says IO", 1, 3, STEPPER.rx, STEPPER.tx, servo=False)
    no_count = GSlave("nservo 0", 1, 4, STEPPER.rx, STEPPER.tx, servo=True, nservo=0)
    layout = build_layout(parse_eni(render([two, io_type, no_count]), "g"))
    assert layout.slaves[0].axes == (1, 2)
    assert layout.slaves[1].axes == ()
    assert layout.slaves[2].axes == (3,)  # nservo 0 says nothing: the objects decide


def test_padding_entries_are_kept_but_not_in_iomap() -> None:
    s = GSlave("pad", 1, 2, [[(0x7000, 1, 1), (0, 0, 7), (0x7000, 2, 8)]], [])
    cfg = parse_eni(render([s]), "g")
    assert [e.bit_len for e in cfg.slaves[0].rx_pdos[0].entries] == [1, 7, 8]
    assert build_layout(cfg).entry(0, 0x7000, 2).gt_bit == 8


_entry = st.tuples(
    st.sampled_from([0x6040, 0x6064, 0x7000, 0x6000, 0x2000, 0x7010]),
    st.integers(1, 40),
    st.sampled_from([1, 2, 8, 16, 32]),
)


@st.composite
def _slaves(draw: st.DrawFn) -> list[GSlave]:
    out = []
    for _ in range(draw(st.integers(1, 4))):

        def pdos() -> list[list[tuple[int, int, int]]]:
            lists = draw(st.lists(st.lists(_entry, min_size=1, max_size=4), max_size=3))
            seen: set[tuple[int, int]] = set()
            clean = []
            for p in lists:
                q = [e for e in p if (e[0], e[1]) not in seen and not seen.add((e[0], e[1]))]
                if q:
                    clean.append(q)
            return clean

        out.append(
            GSlave(
                draw(st.text("abcXYZ_- 0123", min_size=1, max_size=12)).strip() or "s",
                draw(st.integers(0, 0xFFFF)),
                draw(st.integers(0, 0xFFFF)),
                pdos(),
                pdos(),
            )
        )
    return out


@settings(max_examples=examples(60, 15), deadline=None)
@given(
    _slaves(),
    st.builds(
        Noise,
        st.booleans(),
        st.booleans(),
        st.booleans(),
        st.booleans(),
        st.booleans(),
        st.booleans(),
    ),
)
def test_tolerant_parsing_property(slaves: list[GSlave], noise: Noise) -> None:
    """Whatever the spelling noise, the model is the one the items describe."""
    cfg = parse_eni(render(slaves, noise), "noisy.eni")
    layout = build_layout(cfg)
    assert len(cfg.slaves) == len(slaves)
    gt = 0
    for want, got, sl in zip(slaves, cfg.slaves, layout.slaves, strict=True):
        assert got.name == want.name
        assert (got.identity.vendor_id, got.identity.product_code) == (want.vid, want.pcode)
        for pdos, model in ((want.rx, got.rx_pdos), (want.tx, got.tx_pdos)):
            assert [[(e.index, e.subindex, e.bit_len) for e in p.entries] for p in model] == pdos
        # GT raw: outputs then inputs, whole bytes (manual 5.2.2.4)
        rx_bits = sum(b for p in want.rx for _i, _s, b in p)
        tx_bits = sum(b for p in want.tx for _i, _s, b in p)
        assert sl.gt_offset == gt
        assert (sl.out_bytes, sl.in_bytes) == ((rx_bits + 7) // 8, (tx_bits + 7) // 8)
        gt += sl.gt_size
        assert cfg.cycle_time_ns == 1_000_000


def _err(text: str) -> EniError:
    with pytest.raises(EniError) as info:
        parse_eni(text, "Gecat.eni")
    assert info.value.file == "Gecat.eni"
    return info.value


def test_slavenum_mismatch() -> None:
    text = render([IO]).replace("slavenum,Section=DWORD,Value=1", "slavenum,Section=DWORD,Value=2")
    err = _err(text)
    assert err.line == line_of(text, "slavenum") and "2 slaves" in err.message


def test_pdo_count_mismatch() -> None:
    # the SM3 syncitem (3, 2 = inputs, 1 PDO) now claims 3 PDOs
    old, new = "Value=2,Section=DWORD,Value=1\n", "Value=2,Section=DWORD,Value=3\n"
    text = render([IO]).replace(old, new)
    err = _err(text)
    assert "3 PDOs" in err.message and err.slave == 0 and err.line is not None


def test_iomap_disagreeing_with_pdo_lists() -> None:
    text = render([IO])
    bad = text.replace(
        "mapitem,Section=HEX,Value=0x6000,Section=DWORD,Value=2",
        "mapitem,Section=HEX,Value=0x6000,Section=DWORD,Value=3",
    )
    err = _err(bad)
    assert err.line == line_of(bad, "Value=0x6000,Section=DWORD,Value=3")
    assert "slave_iomap" in err.message and err.slave_name == "IO 16/16"


def test_missing_identity_and_bad_values() -> None:
    text = render([IO])
    err = _err(text.replace("name=vid,", "name=vendor,"))
    assert "vid" in err.message and err.line == line_of(text, "[slave_info]")
    err = _err(text.replace("Value=0x1111", "Value=0xZZ"))
    assert err.line == line_of(text, "Value=0x1111") and "HEX" in err.message


def test_pdo_taking_more_entries_than_listed() -> None:
    text = render([IO]).replace(
        "Value=0x1600,Section=DWORD,Value=2", "Value=0x1600,Section=DWORD,Value=5"
    )
    err = _err(text)
    assert "entries" in err.message and err.line == line_of(text, "Value=0x1600")


def test_garbage_line_in_a_slave_section() -> None:
    text = render([IO]).replace("[slave_dc]\n", "[slave_dc]\nthis is not a param line\n")
    err = _err(text)
    assert err.line == line_of(text, "this is not")
