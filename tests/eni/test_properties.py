"""Property tests: layout regions (manual 5.2.2.4 rule) and the writer/reader round trip."""

from __future__ import annotations

from dataclasses import replace
from itertools import pairwise
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gtecat.eni.check import check_config
from gtecat.eni.layout import build_layout
from gtecat.eni.model import Direction, EniConfig, Identity, Pdo, PdoEntry, ProcessDataArea, Slave
from gtecat.eni.reader import parse_eni
from gtecat.eni.topology import build_config
from gtecat.eni.writer import write_eni
from tests.conftest import examples

OUT, IN = Direction.OUT, Direction.IN


# --- arbitrary configurations (unaligned, frame-relative, areas in any order) -------------
@st.composite
def _entries(draw: st.DrawFn, base: int) -> list[list[PdoEntry]]:
    n = draw(st.integers(0, 8))
    sizes = draw(
        st.lists(st.sampled_from([1, 1, 2, 3, 7, 8, 16, 24, 32, 64]), min_size=n, max_size=n)
    )
    pads = draw(st.lists(st.booleans(), min_size=n, max_size=n))
    flat = [
        PdoEntry(0 if pad else base + k, 0 if pad else 1, b)
        for k, (b, pad) in enumerate(zip(sizes, pads, strict=True))
    ]
    cuts = sorted(draw(st.sets(st.integers(1, max(n - 1, 1)), max_size=3))) if n > 1 else []
    groups, last = [], 0
    for c in [*cuts, n]:
        if flat[last:c]:
            groups.append(flat[last:c])
        last = c
    return groups


@st.composite
def configs(draw: st.DrawFn) -> EniConfig:
    n = draw(st.integers(0, 6))
    raw = []
    for pos in range(n):
        rx = draw(_entries(0x7000 + 0x10 * pos))
        tx = draw(_entries(0x6000 + 0x10 * pos))
        raw.append((pos, rx, tx))
    areas: dict[tuple[int, Direction], ProcessDataArea] = {}
    for d in Direction:
        order = draw(st.permutations(range(n)))  # logical order need not be bus order
        cursor = draw(st.integers(0, 64))
        for pos in order:
            groups = raw[pos][1] if d == OUT else raw[pos][2]
            bits = sum(e.bit_len for g in groups for e in g)
            if bits:
                areas[(pos, d)] = ProcessDataArea(cursor, bits)
                cursor += bits + draw(st.integers(0, 20))
    stated = draw(st.booleans())
    slaves = []
    for pos, rx, tx in raw:
        pdos = {}
        for d, groups in ((OUT, rx), (IN, tx)):
            area = areas.get((pos, d))
            bit = area.bit_start if area else 0
            out = []
            for k, g in enumerate(groups):
                es = []
                for e in g:
                    es.append(replace(e, logical_bit=bit) if stated and not e.is_padding else e)
                    bit += e.bit_len
                out.append(Pdo((0x1600 if d == OUT else 0x1A00) + k, d, tuple(es)))
            pdos[d] = tuple(out)
        slaves.append(
            Slave(
                pos,
                f"S{pos}",
                Identity(1, pos),
                rx_pdos=pdos[OUT],
                tx_pdos=pdos[IN],
                outputs=areas.get((pos, OUT)),
                inputs=areas.get((pos, IN)),
            )
        )
    cfg = EniConfig("prop", "xml", tuple(slaves))
    check_config(cfg)
    return cfg


@settings(max_examples=examples(150, 20), deadline=None)
@given(configs())
def test_layout_regions_contiguous_disjoint_and_entries_inside(cfg: EniConfig) -> None:
    layout = build_layout(cfg)
    gt = 0
    used: dict[Direction, list[tuple[int, int]]] = {OUT: [], IN: []}
    for s, sl in zip(cfg.slaves, layout.slaves, strict=True):
        # regions follow each other from 0, outputs then inputs, whole bytes
        assert sl.gt_offset == gt
        assert sl.out_bytes == (s.out_bits + 7) // 8 and sl.in_bytes == (s.in_bits + 7) // 8
        gt += sl.gt_size
        nxt = {OUT: 0, IN: 0}
        for p in sl.entries:
            lo = sl.gt_offset * 8 + (0 if p.direction == OUT else sl.out_bytes * 8)
            hi = lo + (sl.out_bytes if p.direction == OUT else sl.in_bytes) * 8
            assert lo <= p.gt_bit and p.gt_bit + p.bits <= hi
            assert p.gt_bit - lo == p.slave_bit == nxt[p.direction]  # mapping order, packed
            nxt[p.direction] += p.bits
            area = s.outputs if p.direction == OUT else s.inputs
            assert area is not None
            assert area.bit_start <= p.logical_bit
            assert p.logical_bit + p.bits <= area.bit_start + area.bit_len
            assert p.logical_bit - area.bit_start == p.slave_bit  # FMMU copies the area as is
            used[p.direction].append((p.logical_bit, p.logical_bit + p.bits))
            assert p.logical_bit + p.bits <= 8 * (
                layout.outputs_bytes if p.direction == OUT else layout.inputs_bytes
            )
        assert (nxt[OUT], nxt[IN]) == (sl.out_bits, sl.in_bits)
    assert layout.gt_raw_bytes == gt
    for spans in used.values():
        spans.sort()
        assert all(a[1] <= b[0] for a, b in pairwise(spans))


# --- writer -> reader round trip on arbitrary topologies ----------------------------------
_NAME = (
    st.text(
        st.characters(codec="utf-8", categories=("L", "N", "Zs", "P", "S")), min_size=1, max_size=16
    )
    .map(str.strip)
    .filter(bool)
)
_CIA = [
    ("0x6040", 16),
    ("0x6060", 8),
    ("0x607A", 32),
    ("0x60B8", 16),
    ("0x60FF", 32),
    ("0x6071", 16),
]
_CIA_IN = [
    ("0x6041", 16),
    ("0x6061", 8),
    ("0x6064", 32),
    ("0x60B9", 16),
    ("0x60BA", 32),
    ("0x60FD", 32),
    ("0x606C", 32),
]


@st.composite
def _generic_pdos(draw: st.DrawFn, base: int) -> list[dict[str, Any]]:
    pdos = []
    used: set[int] = set()
    for k in range(draw(st.integers(0, 3))):
        entries: list[Any] = []
        for _ in range(draw(st.integers(1, 5))):
            if draw(st.integers(0, 5)) == 0:
                entries.append(f"0:0:{draw(st.integers(1, 15))}")
                continue
            idx = draw(st.integers(0x2000, 0x2FFF).filter(lambda i: i not in used))
            used.add(idx)
            bits = draw(st.sampled_from([1, 2, 5, 8, 16, 32, 64]))
            if draw(st.booleans()):
                entries.append(
                    {
                        "index": idx,
                        "subindex": draw(st.integers(0, 255)),
                        "bits": bits,
                        "name": draw(_NAME),
                    }
                )
            else:
                entries.append(f"{hex(idx)}:{draw(st.integers(0, 255))}:{bits}")
        pdos.append(
            {
                "index": base + k,
                "name": draw(_NAME),
                "entries": entries,
                "fixed": draw(st.booleans()),
            }
        )
    return pdos


@st.composite
def topologies(draw: st.DrawFn) -> dict[str, Any]:
    slaves: list[dict[str, Any]] = []
    for _ in range(draw(st.integers(1, 6))):  # a topology without slaves is refused
        kind = draw(st.sampled_from(["servo", "io", "coupler", "generic"]))
        t: dict[str, Any] = {"kind": kind}
        if draw(st.booleans()):
            t["name"] = draw(_NAME)
        if draw(st.booleans()):
            t["vendor_id"] = draw(st.integers(0, 0xFFFFFFFF))
            t["revision"] = draw(st.integers(0, 0xFFFFFFFF))
        if kind == "servo":
            t["channels"] = draw(st.integers(1, 4))
            rx = draw(st.lists(st.sampled_from(_CIA), min_size=1, unique=True))
            tx = draw(st.lists(st.sampled_from(_CIA_IN), min_size=1, unique=True))
            t["rx"] = [f"{i}:0:{b}" for i, b in rx]
            t["tx"] = [f"{i}:0:{b}" for i, b in tx]
        elif kind == "io":
            t["do"] = draw(st.integers(0, 40))
            t["di"] = draw(st.integers(0, 40))
            t["packing"] = draw(st.sampled_from(["bytes", "bits"]))
        elif kind == "coupler":
            t["coupler_word"] = draw(st.booleans())
            t["modules"] = draw(
                st.lists(
                    st.sampled_from(
                        ["DI8", "DI16", "DI32", "DO8", "DO16", "AI2", "AI4", "AO1", "AO4"]
                    ),
                    max_size=6,
                )
            )
            t["init_cmds"] = draw(st.booleans())
        else:
            t["rx_pdos"] = draw(_generic_pdos(0x1600))
            t["tx_pdos"] = draw(_generic_pdos(0x1A00))
            t["mailbox"] = draw(st.booleans())
        slaves.append(t)
    return {"cycle_time_us": draw(st.integers(50, 100_000)), "master": draw(_NAME), "slave": slaves}


def _norm(cfg: EniConfig) -> EniConfig:
    """Without what only a file states: lines, and the wire layout the writer derives
    (sync manager addresses, mailbox) that a topology does not carry."""
    return replace(
        cfg,
        source="",
        slaves=tuple(
            replace(s, line=None, sync_managers=(), mailbox_layout=None) for s in cfg.slaves
        ),
    )


@settings(
    max_examples=examples(120, 12), deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
@given(topologies())
@pytest.mark.long
def test_write_then_read_gives_the_same_model(topo: dict[str, Any]) -> None:
    cfg = build_config(topo, "topo.toml")
    text = write_eni(cfg)
    back = parse_eni(text, "written.eni")
    assert _norm(back) == _norm(cfg)
    a, b = build_layout(cfg), build_layout(back)
    assert a.slaves == b.slaves and a.axes == b.axes
    assert (a.gt_raw_bytes, a.outputs_bytes, a.inputs_bytes) == (
        b.gt_raw_bytes,
        b.outputs_bytes,
        b.inputs_bytes,
    )
    # and writing the read model again gives the same text
    assert write_eni(back) == text
