"""The N-axis bus generator (tools/gen_axes_eni.py) writes ENIs that read back as N axes."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gtecat.cli.main import main
from gtecat.eni.layout import build_layout
from gtecat.eni.reader import read_eni
from tests.conftest import examples
from tests.eni.test_properties import _norm
from tools import gen_axes_eni
from tools.gen_axes_eni import MAX_AXES, SLAVE_BYTES, axes_config, write_axes_eni

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
    assert MAX_AXES == 65535  # 16-bit station addresses, 0 being none
    with pytest.raises(ValueError, match=rf"1\.\.{MAX_AXES}"):
        write_axes_eni(MAX_AXES + 1, tmp_path / "bus.eni")


@settings(max_examples=examples(40, 6), deadline=None)
@given(n=st.integers(1, 24), modes=st.booleans())
def test_written_bus_reads_back_as_built(n: int, modes: bool) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        back = read_eni(write_axes_eni(n, Path(tmp) / "bus.eni", modes=modes))
    assert _norm(back) == _norm(axes_config(n, modes=modes))
    assert [s.phys_addr for s in back.slaves] == list(range(1001, 1001 + n))
    assert len(build_layout(back).axes) == n


@pytest.mark.parametrize("n", ["65536", "0", "-3"])
def test_beyond_the_range_is_an_error_not_a_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], n: str
) -> None:
    out = tmp_path / "bus.eni"
    assert gen_axes_eni.main(["-o", str(out), "--", n]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"error: axes must be 1..{MAX_AXES}") and "Traceback" not in err
    assert not out.exists()


def test_an_unwritable_output_is_an_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert gen_axes_eni.main(["2", "-o", str(tmp_path / "none" / "bus.eni")]) == 1
    assert capsys.readouterr().err.startswith("error: cannot write ")
