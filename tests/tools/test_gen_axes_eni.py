"""The N-axis bus generator (tools/gen_axes_eni.py) writes ENIs that read back as N axes."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from gtecat.cli.main import main
from gtecat.eni.layout import build_layout
from gtecat.eni.reader import read_eni
from tools.gen_axes_eni import MAX_AXES, SLAVE_BYTES, write_axes_eni

OUT = [(0x6040, 16), (0x607A, 32), (0x6060, 8)]
IN = [(0x6041, 16), (0x6064, 32), (0x60FD, 32), (0x6061, 8)]


@pytest.mark.parametrize("n", [1, 33, 129])  # 129: past the 128 the generator once stopped at
@pytest.mark.long
def test_reader_sees_n_axes(tmp_path: Path, n: int) -> None:
    layout = build_layout(read_eni(write_axes_eni(n, tmp_path / "bus.eni")))
    assert len(layout.axes) == n and len(layout.slaves) == n


@pytest.mark.parametrize("modes", [True, False])
def test_map_offsets(tmp_path: Path, capsys: pytest.CaptureFixture[str], modes: bool) -> None:
    path = write_axes_eni(5, tmp_path / "bus.eni", modes=modes)
    assert main(["map", str(path), "--json"]) == 0
    m = json.loads(capsys.readouterr().out)
    size = SLAVE_BYTES[modes]
    assert m["gt_raw_bytes"] == 5 * size
    out, inp = (OUT, IN) if modes else (OUT[:2], IN[:3])
    for k, s in enumerate(m["slaves"]):
        where = (s["position"], s["axis"], s["gt_offset"], s["gt_size"])
        assert where == (k, k + 1, k * size, size)
        got = [(e["dir"], e["index"], e["bits"], e["gt_bit"]) for e in s["entries"]]
        want, bit = [], k * size * 8
        for d, entries in (("out", out), ("in", inp)):
            for index, bits in entries:
                want.append((d, index, bits, bit))
                bit += bits
        assert got == want


def test_range(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=rf"1\.\.{MAX_AXES}"):
        write_axes_eni(MAX_AXES + 1, tmp_path / "bus.eni")
