"""The GT raw view over the logical images (manual 5.2.2.4, DESIGN.md "Process image").

Property tests: for random topologies (byte- and bit-aligned, zero-based and
out-of-order logical areas), every raw read/write at any offset agrees with an
independent model that packs each slave's outputs then inputs LSB first.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.eni.bits import get_bits, set_bits
from gtecat.eni.layout import build_layout
from gtecat.eni.model import (
    Direction,
    EniConfig,
    Identity,
    Pdo,
    PdoEntry,
    ProcessDataArea,
    Slave,
)
from gtecat.errors import ParameterError
from gtecat.master.image import ProcessImage
from tests.conftest import examples


@st.composite
def configs(draw):
    n = draw(st.integers(1, 5))
    aligned = draw(st.booleans())
    slaves, out_bit, in_bit = [], 0, 0
    for pos in range(n):
        areas = {}
        pdos = {}
        for d in (Direction.OUT, Direction.IN):
            sizes = draw(st.lists(st.sampled_from([1, 3, 8, 16, 32]), min_size=0, max_size=4))
            entries = tuple(
                PdoEntry(0x7000 if d == Direction.OUT else 0x6000, k + 1, b, f"e{k}", "")
                for k, b in enumerate(sizes)
            )
            pdos[d] = (
                (Pdo(0x1600 if d == Direction.OUT else 0x1A00, d, entries, sm=2 + d),)
                if entries
                else ()
            )
            bits = sum(sizes)
            start = out_bit if d == Direction.OUT else in_bit
            if aligned:
                start = (start + 7) // 8 * 8
            areas[d] = ProcessDataArea(start, bits) if bits else None
            if d == Direction.OUT:
                out_bit = start + bits
            else:
                in_bit = start + bits
        slaves.append(
            Slave(
                pos,
                f"S{pos}",
                Identity(1, 2),
                rx_pdos=pdos[Direction.OUT],
                tx_pdos=pdos[Direction.IN],
                outputs=areas[Direction.OUT],
                inputs=areas[Direction.IN],
            )
        )
    return EniConfig(
        "mem",
        "xml",
        tuple(slaves),
        outputs_bytes=(out_bit + 7) // 8 + 1,
        inputs_bytes=(in_bit + 7) // 8 + 1,
    )


def _model_raw(image: ProcessImage) -> bytes:
    """Independent GT raw image: per slave, its output bits then its input bits."""
    raw = bytearray()
    for s in image.layout.config.slaves:
        for d, area in ((Direction.OUT, s.outputs), (Direction.IN, s.inputs)):
            if area is None:
                continue
            base = 0 if d == Direction.OUT else image.outputs_bytes * 8
            v = get_bits(image.view, base + area.bit_start, area.bit_len)
            raw += v.to_bytes((area.bit_len + 7) // 8, "little")
    return bytes(raw)


@settings(max_examples=examples(60, 15), deadline=None)
@given(configs(), st.data())
def test_raw_reads_match_the_model(cfg, data):
    image = ProcessImage(build_layout(cfg))
    n = len(image.buffer)
    image.buffer[:] = np.frombuffer(data.draw(st.binary(min_size=n, max_size=n)), np.uint8)
    model = _model_raw(image)
    assert image.size == len(model)
    if not model:
        return
    off = data.draw(st.integers(0, len(model) - 1))
    size = data.draw(st.integers(0, len(model) - off))
    assert image.read_raw(off, size) == model[off : off + size]


@settings(max_examples=examples(60, 15), deadline=None)
@given(configs(), st.data())
def test_raw_writes_land_in_outputs_only(cfg, data):
    image = ProcessImage(build_layout(cfg))
    if not image.size:
        return
    before = bytes(image.buffer)
    off = data.draw(st.integers(0, image.size - 1))
    size = data.draw(st.integers(1, image.size - off))
    payload = data.draw(st.binary(min_size=size, max_size=size))
    touches_inputs = not image._raw_is_out[off : off + size].all()
    if touches_inputs:
        with pytest.raises(ParameterError):
            image.write_raw(off, payload)
        assert bytes(image.buffer) == before  # refused writes change nothing
        return
    image.write_raw(off, payload)
    got = image.read_raw(off, size)
    # bits beyond a slave's last entry (byte padding) are not stored anywhere
    for seg in image.segments:
        if seg.direction != Direction.OUT:
            continue
        lo, hi = max(off, seg.raw_offset), min(off + size, seg.raw_offset + seg.raw_bytes)
        for b in range(lo, hi):
            nbits = min(8, seg.bit_len - (b - seg.raw_offset) * 8)
            mask = (1 << nbits) - 1
            assert got[b - off] & mask == payload[b - off] & mask
    # the input image is untouched
    assert bytes(image.inputs) == before[image.outputs_bytes :]


def test_out_of_range_is_refused():
    cfg = EniConfig(
        "mem",
        "xml",
        (
            Slave(
                0,
                "S",
                Identity(1, 2),
                rx_pdos=(Pdo(0x1600, Direction.OUT, (PdoEntry(0x7000, 1, 16),)),),
                outputs=ProcessDataArea(0, 16),
            ),
        ),
        outputs_bytes=2,
    )
    image = ProcessImage(build_layout(cfg))
    for off, size in ((0, 3), (2, 1), (-1, 1)):
        with pytest.raises(ParameterError, match="outside"):
            image.read_raw(off, size)


def test_typed_entry_access_wraps_like_c():
    cfg = EniConfig(
        "mem",
        "xml",
        (
            Slave(
                0,
                "S",
                Identity(1, 2),
                rx_pdos=(
                    Pdo(
                        0x1600,
                        Direction.OUT,
                        (PdoEntry(0x607A, 0, 32, "", "DINT"), PdoEntry(0x7000, 1, 3, "", "")),
                    ),
                ),
                outputs=ProcessDataArea(0, 35),
            ),
        ),
        outputs_bytes=5,
    )
    layout = build_layout(cfg)
    image = ProcessImage(layout)
    tp = image.access(layout.entry(0, 0x607A, 0))
    tp.set(-5)
    assert tp.get() == -5
    tp.set(1 << 31)  # wraps to INT32_MIN like a C int
    assert tp.get() == -(1 << 31)
    bits = image.access(layout.entry(0, 0x7000, 1))
    bits.set(0b101)
    assert bits.get() == 0b101 and image.read_raw(4, 1) == b"\x05"
    set_bits(image.view, 32, 3, 0)
    assert bits.get() == 0
