"""tools/bench_dc_frame.py runs: the chain ``gtecat serve`` builds comes up to OP with SOEM's
register writes and DC set-up, and every frame shape answers with the expected working
counters (the tool checks them and stops otherwise)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tools.bench_dc_frame import SHAPES, run_shape

FIG52 = Path(__file__).resolve().parents[2] / "examples" / "manual_fig5_2.eni"


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.sample(1)
def test_each_shape_runs_and_reports(shape: str) -> None:
    got = run_shape(FIG52, shape, 30)
    assert got["slaves"] == 4 and got["frames"] == 30
    assert 0 < got["p50_us"] <= got["p99_us"] <= got["max_us"]
