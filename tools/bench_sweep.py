"""Sweep engine overhead and scaling, in one run: the homing example's cases run

* alone: one after another in this process (``run_case``, no engine),
* through Dask with one local worker, and with two,

and prints JSON: cases/s of each, the cost per case through the engine against alone
(target <= 1.5x) and the speed-up of two workers over one (target >= 1.7x; needs two idle
CPUs). Cluster start-up is left out (it is paid once per sweep, not per case).

    python3 tools/bench_sweep.py [--cases 60]
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
import tempfile
import time
from importlib import resources
from pathlib import Path


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=60)
    args = ap.parse_args()
    from dask.distributed import Client, LocalCluster

    from gtecat.sweep.case import Job, run_case
    from gtecat.sweep.engine import run_cases
    from gtecat.sweep.grid import load_grid
    from gtecat.sweep.results import ResultsWriter

    folder = Path(tempfile.mkdtemp(prefix="bench-sweep-"))
    shipped = resources.files("gtecat") / "examples"
    for name in ("sweep_homing.py", "sweep_homing.toml", "sweep_homing_machine.toml"):
        (folder / name).write_bytes(shipped.joinpath(name).read_bytes())
    grid = load_grid(folder / "sweep_homing.toml")
    cases = grid.cases()[: args.cases]
    job = Job.from_files(folder / "sweep_homing.py", grid)
    run_case(job, cases[0])  # warm: imports, the bank kernel's build
    t0 = time.perf_counter()
    for case in cases:
        run_case(job, case)
    alone = len(cases) / (time.perf_counter() - t0)
    out: dict[str, object] = {"cases": len(cases), "cpus": os.cpu_count(), "alone_cases_s": alone}
    for n in (1, 2):
        with (
            LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                silence_logs=logging.ERROR,
            ) as cluster,
            Client(cluster) as client,
        ):
            client.run(run_case, job, cases[0])  # warm every worker as above
            writer = ResultsWriter(folder / f"r{n}.csv")
            t0 = time.perf_counter()
            run_cases(client, job, cases, writer)
            out[f"workers{n}_cases_s"] = len(cases) / (time.perf_counter() - t0)
            writer.close()
    out["cost_per_case_vs_alone"] = alone / out["workers1_cases_s"]  # type: ignore[operator]
    out["two_workers_speedup"] = out["workers2_cases_s"] / out["workers1_cases_s"]  # type: ignore[operator]
    json.dump(out, sys.stdout, indent=1)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
