"""The cyclic frames the writer writes: each fits one Ethernet frame (ETG.1000.4 5.3, built
here by the frame codec), the commands cover each image exactly once at the right logical
addresses, and each ``Cnt`` is the working counter the slaves return (5.4), counted here from
the slaves' ``Send``/``Recv`` areas, not from the FMMUs the writer counts from."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gtecat.drives.esc.frames import MAX_ECAT_LEN, Datagram, encode_frame
from gtecat.eni.cyclic import MAX_DATAGRAM_DATA, cyclic_frames
from gtecat.eni.ethercat import Command
from gtecat.eni.layout import build_layout
from gtecat.eni.model import Direction, EniConfig
from gtecat.eni.reader import parse_eni
from gtecat.eni.register_cmds import logical_bases
from gtecat.eni.topology import build_config
from gtecat.eni.writer import write_eni
from tests.conftest import examples
from tests.eni.test_properties import _norm
from tools.gen_axes_eni import axes_config

_CIA_RX = ["0x6040:0:16", "0x607A:0:32", "0x60FF:0:32", "0x6060:0:8", "0x60B8:0:16"]
_CIA_TX = ["0x6041:0:16", "0x6064:0:32", "0x60FD:0:32", "0x6061:0:8", "0x60B9:0:16"]


@st.composite
def slave_kinds(draw: st.DrawFn) -> dict[str, Any]:
    """One slave of a kind that the bus repeats: a drive, digital IO (whole bytes or bit
    packed, so that slaves share bytes), or a device with one large entry (an area larger
    than a datagram is cut inside it)."""
    kind = draw(st.sampled_from(["servo", "io", "big"]))
    if kind == "servo":
        rx = draw(st.lists(st.sampled_from(_CIA_RX), min_size=1, unique=True))
        tx = draw(st.lists(st.sampled_from(_CIA_TX), min_size=1, unique=True))
        return {"kind": "servo", "rx": rx, "tx": tx}
    if kind == "io":
        packing = draw(st.sampled_from(["bytes", "bits"]))
        most = 2040 if packing == "bytes" else 255  # a bit a subindex
        return {
            "kind": "io",
            "do": draw(st.integers(0, most)),
            "di": draw(st.integers(0, most)),
            "packing": packing,
        }
    out, inp = draw(st.integers(0, 24_000)), draw(st.integers(0, 24_000))
    return {
        "kind": "generic",
        "rx_pdos": [{"index": 0x1600, "entries": [f"0x2000:1:{out}"]}] if out else [],
        "tx_pdos": [{"index": 0x1A00, "entries": [f"0x2001:1:{inp}"]}] if inp else [],
    }


#: the longest run of one kind of slave
_RUN = examples(150, 50)


@st.composite
def buses(draw: st.DrawFn) -> EniConfig:
    """A bus of 1..~600 slaves (~200 in the default run, which draws twice as many buses:
    as many of them past a frame as ten of the larger ones, at less than half the cost): a
    few kinds, each repeated, in runs."""
    slaves: list[dict[str, Any]] = []
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(slave_kinds())
        most = _RUN if kind["kind"] != "generic" else 3
        slaves += [kind] * draw(st.integers(1, most))
    return build_config({"cycle_time_us": 1000, "slave": slaves}, "bus.toml")


def _bytes(bit_start: int, bit_len: int) -> tuple[int, int]:
    return bit_start // 8, (bit_start + bit_len + 7) // 8


def _areas(cfg: EniConfig, d: Direction) -> list[tuple[int, int]]:
    """Each slave's bytes in a direction's image, from its Send/Recv area."""
    out = []
    for s in cfg.slaves:
        area = s.outputs if d == Direction.OUT else s.inputs
        if area is not None and area.bit_len:
            out.append(_bytes(area.bit_start, area.bit_len))
    return out


def check_frames(cfg: EniConfig) -> list[list[Any]]:
    frames = cyclic_frames(cfg)
    bases = logical_bases(cfg.outputs_bytes)
    for frame in frames:
        assert frame
        raw = encode_frame([Datagram.logical(c.command, c.address, bytes(c.length)) for c in frame])
        assert len(raw) <= 14 + MAX_ECAT_LEN  # 1514 bytes without FCS
    cmds = [c for f in frames for c in f]
    for d, command, size in (
        (Direction.OUT, Command.LWR, cfg.outputs_bytes),
        (Direction.IN, Command.LRD, cfg.inputs_bytes),
    ):
        mine = sorted((c for c in cmds if c.direction == d), key=lambda c: c.offset)
        assert all(c.command == command and c.length > 0 for c in mine)
        # consecutive, from byte 0 to the image's end: every byte exactly once
        assert [c.offset for c in mine] == [0, *(c.offset + c.length for c in mine)][: len(mine)]
        assert sum(c.length for c in mine) == size
        assert all(c.address == bases[d] + c.offset for c in mine)
        areas = _areas(cfg, d)
        for c in mine:
            end = c.offset + c.length
            assert c.wkc == sum(1 for a, b in areas if a < end and c.offset < b), c
        # a command ends inside a slave's bytes only where bytes shared by slaves make a run
        # longer than one datagram holds
        runs: list[list[int]] = []
        for a, b in sorted(areas):
            if runs and a < runs[-1][1]:
                runs[-1][1] = max(runs[-1][1], b)
            else:
                runs.append([a, b])
        for c in mine[1:]:
            for a, b in runs:
                if a < c.offset < b:
                    assert b - a > MAX_DATAGRAM_DATA, (c, a, b)
    need = sum(12 + n for n in (cfg.outputs_bytes, cfg.inputs_bytes) if n)
    if not need:
        assert frames == []
    elif 2 + need <= MAX_ECAT_LEN:  # what fits one frame is one frame, one command a direction
        assert len(frames) == 1 and len(cmds) == bool(cfg.outputs_bytes) + bool(cfg.inputs_bytes)
    return frames


@settings(
    max_examples=examples(150, 20), deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
@given(buses())
def test_every_frame_fits_and_the_commands_cover_each_image_once(cfg: EniConfig) -> None:
    check_frames(cfg)


def _cyclic_xml(text: str) -> list[list[dict[str, int | str]]]:
    root = ET.fromstring(text)
    return [
        [
            {
                tag: int(c.findtext(tag) or 0)
                for tag in ("Cmd", "Addr", "DataLength", "Cnt", "InputOffs", "OutputOffs")
            }
            | {"Comment": c.findtext("Comment") or ""}
            for c in f.findall("Cmd")
        ]
        for f in root.findall("Config/Cyclic/Frame")
    ]


def test_300_drives_take_four_frames() -> None:
    """300 drives: 2,100 output bytes (7 each) and 3,300 input bytes (11 each), 5,400 bytes:
    four frames (the file writes them as laid out here: the test below)."""
    frames = check_frames(axes_config(300))
    assert [[(int(c.command), c.length, c.wkc) for c in f] for f in frames] == [
        [(11, 1484, 212)],  # 212 whole drives: 1,484 bytes, the most one datagram holds
        [(11, 616, 88), (10, 847, 77)],  # 2 + 628 + 859 = 1,489 bytes: a 78th drive won't fit
        [(10, 1474, 134)],
        [(10, 979, 89)],
    ]


@pytest.mark.parametrize(
    "drives",
    [
        90,  # two frames, the inputs cut between them
        pytest.param(300, marks=pytest.mark.long("the 300 drives above; 90 run by default")),
    ],
)
def test_several_frames_are_written_as_laid_out_and_read_back(drives: int) -> None:
    """The file writes each frame's commands as laid out (a command that carries a whole
    image says so, one cut from it names its bytes); read back it gives the same model and
    process image."""
    cfg = axes_config(drives)
    frames = check_frames(cfg)
    assert len(frames) > 1
    size = {Direction.OUT: cfg.outputs_bytes, Direction.IN: cfg.inputs_bytes}
    text = write_eni(cfg)
    assert _cyclic_xml(text) == [
        [
            {
                "Cmd": int(c.command),
                "Addr": c.address,
                "DataLength": c.length,
                "Cnt": c.wkc,
                "InputOffs": c.offset,
                "OutputOffs": c.offset,
                "Comment": f"process data {'outputs' if c.direction == Direction.OUT else 'inputs'}"
                + (
                    ""
                    if c.length == size[c.direction]
                    else f" {c.offset}..{c.offset + c.length - 1}"
                ),
            }
            for c in f
        ]
        for f in frames
    ]
    back = parse_eni(text, f"{drives}.eni")
    assert _norm(back) == _norm(cfg)
    mine, theirs = build_layout(cfg), build_layout(back)
    assert (mine.slaves, mine.gt_raw_bytes, mine.outputs_bytes, mine.inputs_bytes) == (
        theirs.slaves,
        theirs.gt_raw_bytes,
        theirs.outputs_bytes,
        theirs.inputs_bytes,
    )


def test_a_bus_that_fits_one_frame_keeps_one_lwr_and_one_lrd() -> None:
    """64 drives: 448 + 704 bytes, 1,178 bytes of datagrams: the frame written before."""
    assert _cyclic_xml(write_eni(axes_config(64))) == [
        [
            {
                "Cmd": 11,
                "Addr": 0x10000000,
                "DataLength": 448,
                "Cnt": 64,
                "InputOffs": 0,
                "OutputOffs": 0,
                "Comment": "process data outputs",
            },
            {
                "Cmd": 10,
                "Addr": 0x10000800,
                "DataLength": 704,
                "Cnt": 64,
                "InputOffs": 0,
                "OutputOffs": 0,
                "Comment": "process data inputs",
            },
        ]
    ]
