"""Sweeps: one scenario over many machine variants, on this machine or on a Dask cluster.

``gtecat sweep SCENARIO.py --grid GRID.toml`` runs every case (:mod:`gtecat.sweep.grid`
says what a grid holds); :func:`run_one` runs one case of the same scenario in this process,
so the scenario is also a pytest test::

    from gtecat.sweep import run_one
    from homing_sweep import scenario

    def test_nominal_machine():
        values = run_one(scenario, "grid.toml", method=19, speed=40000)
        assert values["error_counts"] == 0
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from pathlib import Path
from typing import Any

from .grid import Case, Grid, load_grid

__all__ = ["Case", "Grid", "load_grid", "run_one"]


def run_one(
    scenario: Callable[..., Any] | str | Path,
    grid: str | Path,
    case_id: str | None = None,
    **params: Any,
) -> dict[str, Any]:
    """Run one case (by id, else the given parameters, else the grid's first case) here.

    Returns the scenario's values; raises AssertionError with the case's traceback when it
    fails, so a pytest test fails with the scenario's own reason."""
    from .case import Job, run_case

    g = load_grid(grid)
    if case_id is not None:
        case = g.find(case_id)
    elif params:
        case = Case(params)
    else:
        cases = g.cases()
        case = cases[0]
    if callable(scenario):
        path = Path(inspect.getsourcefile(scenario) or "scenario.py")
        job = Job(
            str(path), path.read_text(encoding="utf-8"), g.eni, g.eni_bytes, g.machine, g.card
        )
    else:
        job = Job.from_files(scenario, g)
    row = run_case(job, case)
    if not row["ok"]:
        raise AssertionError(f"case {case.id} {case.params} failed:\n{row['error']}")
    skip = {"id", "seed", "ok", "error", "seconds", "kept", *case.params}
    return {k: v for k, v in row.items() if k not in skip}
