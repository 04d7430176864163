"""``gtecat sweep``: run one scenario over many machine variants, on Dask.

  gtecat sweep scenario.py --grid grid.toml -o results.parquet
                                  every case of the grid, one worker process per CPU
  gtecat sweep scenario.py --grid grid.toml -o results.csv --scheduler tcp://10.0.0.5:8786
                                  the same on a running Dask scheduler's workers
  gtecat sweep scenario.py --grid grid.toml --list
                                  the cases (id, seed, parameters) without running them
  gtecat sweep scenario.py --grid grid.toml --case 3f2a9c1b7d40
                                  one case alone, in this process, with its seed
  gtecat sweep report results.parquet -o report/
                                  an HTML page and PNGs of the results

A scenario is a Python file with ``def scenario(gt, case):`` returning a dict of measured
values (raise, or return ``ok=False``, on failure). Each case runs in a fresh controller in
the lockstep clock, opened and in OP. Running again with the same results file computes only
the cases missing from it. ``gtecat example sweep_homing`` writes a complete sweep.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ..errors import ParameterError
from . import output


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "sweep",
        help="run a scenario over a grid of machine variants (Dask), or report the results",
        description=output.describe(__doc__),
        epilog="examples:\n"
        "  gtecat example sweep_homing -o sw             (then in sw/:)\n"
        "  gtecat sweep sweep_homing.py --grid sweep_homing.toml --list\n"
        "  gtecat sweep sweep_homing.py --grid sweep_homing.toml -o results.parquet\n"
        "  gtecat sweep report results.parquet -o report/",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("scenario", metavar="SCENARIO.py|report", help="the scenario file, or 'report'")
    p.add_argument("results_file", nargs="?", metavar="RESULTS", help="(report) the results file")
    p.add_argument("--grid", metavar="GRID.toml", help="the grid of cases")
    p.add_argument(
        "-o", "--output", metavar="PATH", help="results file (.parquet or .csv); report: a folder"
    )
    p.add_argument("--scheduler", metavar="ADDR", help="a running Dask scheduler (tcp://HOST:PORT)")
    p.add_argument(
        "--workers", type=int, metavar="N", help="local worker processes (default: CPUs)"
    )
    p.add_argument("--case", metavar="ID", help="run this one case alone and print its row")
    p.add_argument("--list", action="store_true", help="list the cases without running them")
    p.add_argument("--x", metavar="PARAM", help="(report) parameter on the map's x axis")
    p.add_argument("--y", metavar="PARAM", help="(report) parameter on the map's y axis")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.scenario == "report" and not Path("report").is_file():
        return _report(args)
    from ..sweep.case import Job, run_case
    from ..sweep.grid import load_grid

    if not args.grid:
        raise ParameterError("give the cases with --grid GRID.toml")
    scenario = Path(args.scenario)
    if not scenario.is_file():
        raise ParameterError(f"{scenario}: scenario file not found")
    grid = load_grid(args.grid)
    grid.check()
    _check_scenario(scenario)
    cases = grid.cases()
    if args.list:
        for case in cases:
            print(case.id, case.seed, json.dumps(case.params))
        return 0
    if args.case:
        row = run_case(Job.from_files(scenario, grid), grid.find(args.case))
        error = row.pop("error", "")
        print(json.dumps(row, default=str))
        if not row["ok"]:
            print(error, file=sys.stderr, end="" if error.endswith("\n") else "\n")
        return 0 if row["ok"] else 1
    return _sweep(args, scenario, grid, cases)


def _check_scenario(scenario: Path) -> None:
    """The scenario compiles and defines ``scenario(gt, case)``: refused here, with the
    reason, rather than failing every case alike on the workers."""
    from ..sweep.case import load_scenario

    try:
        load_scenario(str(scenario), scenario.read_text(encoding="utf-8"))
    except SyntaxError as e:
        raise ParameterError(f"{scenario}:{e.lineno}: {e.msg}") from None
    except Exception as e:  # what its top level raises is the user's
        raise ParameterError(f"{scenario}: {type(e).__name__}: {e}") from None


def _sweep(args: argparse.Namespace, scenario: Path, grid, cases) -> int:
    from ..sweep import results
    from ..sweep.case import Job
    from ..sweep.engine import Progress, client_for, run_cases

    if args.workers is not None and args.workers < 1:
        raise ParameterError("--workers must be 1 or more")
    out = results.check_path(args.output or f"{Path(args.grid).stem}.parquet")
    done = results.read_rows(out)
    before = results.read_meta(out).get("scenario_sha")
    if done and before and before != results.scenario_sha(scenario):
        failed = [r for r in done if not r.get("ok")]
        if failed:
            print(
                f"{scenario} changed since {out} was written: its {len(failed)} failed "
                "case(s) run again",
                file=sys.stderr,
            )
            done = [r for r in done if r.get("ok")]
    done_ids = {str(r["id"]) for r in done}
    todo = [c for c in cases if c.id not in done_ids]
    keep = out.with_name(out.stem + ".failures")
    results.write_meta(out, scenario, Path(args.grid))
    print(
        f"{len(cases)} cases, {len(cases) - len(todo)} already in {out}, {len(todo)} to run",
        file=sys.stderr,
    )
    writer = results.ResultsWriter(out, done)
    progress = Progress(len(todo))
    client = None
    try:
        if todo:
            client = client_for(args.scheduler, args.workers)
            run_cases(
                client, Job.from_files(scenario, grid, str(keep.resolve())), todo, writer, progress
            )
    except KeyboardInterrupt:
        writer.close()
        print(
            f"\ninterrupted: {progress.done} cases written to {out}; run the same command "
            "again to compute the rest",
            file=sys.stderr,
        )
        return 130
    finally:
        if client is not None:
            cluster = getattr(client, "cluster", None)
            client.close()
            if cluster is not None:
                cluster.close()
    writer.close()
    failed = [r for r in writer.rows if not r.get("ok")]
    print(f"{len(writer.rows)} cases in {out}: {len(failed)} failed", file=sys.stderr)
    for row in failed[:5]:
        print(
            f"  rerun: gtecat sweep {scenario} --grid {args.grid} --case {row['id']}",
            file=sys.stderr,
        )
    return 1 if failed else 0


def _report(args: argparse.Namespace) -> int:
    from ..sweep.report import write_report

    if not args.results_file:
        raise ParameterError("gtecat sweep report RESULTS [-o DIR]: give the results file")
    out = Path(args.output or Path(args.results_file).stem + "-report")
    page = write_report(Path(args.results_file), out, x=args.x, y=args.y)
    print(f"wrote {page}")
    return 0
