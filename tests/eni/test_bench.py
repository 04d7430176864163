"""The ENI-read benchmark function (tools/bench_eni.py) runs and measures the right file."""

from __future__ import annotations

import pytest

from tools.bench_eni import bench_read


@pytest.mark.long
def test_bench_read_64_slaves() -> None:
    r = bench_read(64, repeat=1)
    assert r["name"] == "eni_read" and r["n_slaves"] == 64
    # 8 DI16/DO16 terminals, 8 four-axis modules, 48 single drives -> 48 + 32 axes
    assert r["axes"] == 80
    assert r["file_bytes"] > 100_000
    assert 0 < r["seconds"] and r["target_seconds"] == 0.3
    assert r["ok"] == (r["seconds"] < 0.3)
