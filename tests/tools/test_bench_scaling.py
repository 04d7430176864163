"""The scaling and issue-17 benchmarks run for a moment and return well-formed results.

No timing assertions: speed is measured by the benchmarks, not by tests.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tools import bench, bench_scaling
from tools.bench_scaling import BenchError, bench_point, core_axis, gtn, write_plot, write_table

FIGURES = {"cycles_per_s", "rtf", "us_per_cycle", "us_per_axis", "bringup_s"}


@pytest.mark.parametrize(
    ("axis", "expected"),
    [(1, (1, 1)), (32, (1, 32)), (33, (2, 1)), (64, (2, 32)), (65, (3, 1)), (128, (4, 32))],
)
def test_core_axis(axis: int, expected: tuple[int, int]) -> None:
    assert core_axis(axis) == expected


@pytest.mark.parametrize("state", bench_scaling.STATES)
def test_point_is_well_formed(state: str) -> None:
    r = bench_point(2, state, seconds=0.02, repeat=1)
    assert r["axes"] == 2 and r["state"] == state and r["addressing"] == "cores"
    assert FIGURES <= r.keys(), r.get("error")
    assert all(isinstance(r[k], float) and r[k] > 0 for k in FIGURES)
    json.dumps(r)


@pytest.mark.parametrize("state", bench_scaling.MODES)
def test_mode_point_is_well_formed(state: str) -> None:
    """PT, Gear, Follow, crd on 4 axes: every axis of the plan still moving at the end."""
    r = bench_point(4, state, seconds=0.02, repeat=1)
    assert FIGURES <= r.keys(), r.get("error")


def test_crd_plan_takes_four_axes_per_core() -> None:
    plan = bench_scaling.crd_plan(40)
    assert [a for a, s in plan.items() if s == "crd"] == [1, 2, 3, 4, 33, 34, 35, 36]


def test_pt_and_mixed_plan() -> None:
    r = bench_scaling.run_bus(3, {1: "pt", 2: "moving"}, seconds=0.02, repeat=1)
    assert FIGURES <= r.keys(), r.get("error")


def test_axis_beyond_32_names_its_core(tmp_path: Path) -> None:
    from gtecat import gt
    from tools.gen_axes_eni import write_axes_eni

    bench_scaling.bring_up(write_axes_eni(1, tmp_path / "one.eni"), 1)
    try:
        # (core 2 of a bus this small is the card's second core, a pulse core of its own)
        with pytest.raises(BenchError, match=r"GTN_AxisOn\(3, 1\) for bus axis 65"):
            gtn("AxisOn", 65)
    finally:
        gt.GT_Close()


@pytest.mark.long
def test_table_and_plot(tmp_path: Path) -> None:
    results = [
        {"axes": 1, "state": "idle", "rtf": 20.0, "us_per_cycle": 50.0},
        {"axes": 1, "state": "moving", "rtf": 16.0, "us_per_cycle": 62.0},
        {"axes": 64, "state": "idle", "error": "core 2 missing"},
    ]
    write_table(results, tmp_path / "t.md")
    text = (tmp_path / "t.md").read_text(encoding="utf-8")
    assert "| 1 | 50 | 20.00× | 62 | 16.00× |" in text
    assert "| 64 | n/a | n/a | n/a | n/a |" in text and "core 2 missing" in text
    page = tmp_path / "page.md"
    page.write_text(f"# title\n{bench_scaling.BEGIN}\nold\n{bench_scaling.END}\ntail\n")
    write_table(results, page)
    text = page.read_text(encoding="utf-8")
    assert text.startswith("# title\n") and text.endswith(f"{bench_scaling.END}\ntail\n")
    assert "old" not in text and "| 64 | n/a |" in text
    write_plot(results, tmp_path / "p.png")
    assert (tmp_path / "p.png").read_bytes()[:4] == b"\x89PNG"


def test_get_sts_ratio_is_well_formed() -> None:
    r = bench._figure(bench.bench_get_sts(0.02, block=20), "ratio", 4, at_most=True)
    assert r["target"] == 4 and isinstance(r["ok"], bool)
    assert r["gt_get_sts_us"] > 0 and r["argument_us"] > 0 and r["blocks"] >= 1


def test_every_shape_is_well_formed() -> None:
    """Every function with a fast path in every client shape: each call answers 0 or is
    reported apart with why (an object the bus does not map, a recorded slow shape)."""
    from gtecat.gt import fast

    r = bench.bench_every_shape(0.05, block=2)
    assert r["count"] == len(r["shapes"]) > 100 and r["worst"] > 0
    names = {k.split("(")[0] for k in [*r["shapes"], *r["not_measured"]]}
    assert names == set(fast.fast_functions() - fast.RAW)
    assert all(v["call_us"] > 0 and v["argument_us"] > 0 for v in r["shapes"].values())
    assert set(r["above_4"]) <= set(r["shapes"])
    apart = [k.split("(")[0] for k, why in r["not_measured"].items() if "table path" in why]
    assert sorted(apart) == sorted(n for n, kinds in fast.SLOW_SHAPES.items() for _ in kinds)


def test_figure_error_is_not_ok() -> None:
    assert bench._figure({"error": "x"}, "rtf", 10) == {"error": "x", "target": 10, "ok": False}
    assert bench._figure({"rtf": 12.0}, "rtf", 10)["ok"] is True
    assert bench._rss()["VmRSS_mb"] > 0


def test_drive_homing_runs_to_its_end() -> None:
    """Two axes homed by their drives (method 17) from the start to the end."""
    r = bench_scaling.run_drive_homing(2, 17, repeat=1)
    assert "error" not in r
    assert r["controller_ms"] > 0 and r["rtf"] > 0 and r["rtf_cpu"] > 0
