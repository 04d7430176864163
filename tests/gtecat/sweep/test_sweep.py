"""gtecat sweep end to end: local Dask workers, a real scheduler with a killed worker, resume,
one case by id, the pytest face, the report."""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from gtecat.cli.main import main
from gtecat.sweep import run_one
from gtecat.sweep.results import read_rows

# skipped without importing them: collecting this file in every xdist worker must not cost
# Dask's import (most workers never run these tests)
pytestmark = [
    pytest.mark.xdist_group("sweep"),
    pytest.mark.skipif(
        importlib.util.find_spec("distributed") is None,
        reason="needs Dask: pip install 'gtecat[sweep]'",
    ),
    pytest.mark.skipif(
        importlib.util.find_spec("pyarrow") is None,
        reason="needs pyarrow: pip install 'gtecat[sweep]'",
    ),
]

#: a Trap move of `distance` on axis 1; fails where the machine's positive limit is in the way
SCENARIO = """
from ctypes import byref, c_double, c_long

from gtecat.gt import TTrapPrm


def scenario(gt, case):
    def check(rc):
        if rc != 0:
            raise RuntimeError(gt.GTE_GetLastError())

    check(gt.GT_AxisOn(1))
    check(gt.GT_PrfTrap(1))
    prm = TTrapPrm(acc=1.0, dec=1.0, velStart=0, smoothTime=0)
    check(gt.GT_SetTrapPrm(1, byref(prm)))
    check(gt.GT_SetPos(1, case["distance"]))
    check(gt.GT_SetVel(1, 50.0))
    check(gt.GT_Update(1))
    gt.GTE_Wait(case.get("wait_ms", 300))
    pos = c_double()
    check(gt.GT_GetPrfPos(1, byref(pos)))
    sts = c_long()
    check(gt.GT_GetSts(1, byref(sts)))
    limit = bool(sts.value & (1 << 5))  # positive limit triggered (manual table 6-1)
    return {"prf_pos": pos.value, "limit": limit, "ok": not limit}
"""

MACHINE = "[axis.1]\nposition = 0\npositive_limit = 5000\n"


@pytest.fixture
def sweep_dir(tmp_path: Path) -> Path:
    (tmp_path / "scenario.py").write_text(SCENARIO)
    (tmp_path / "m.toml").write_text(MACHINE)
    (tmp_path / "grid.toml").write_text(
        '[base]\neni = "manual_fig5_2"\nmachine = "m.toml"\n'
        '[grid]\ndistance = [1000, 3000, 8000]\n"machine.axis.1.positive_limit" = [5000, 9000]\n'
    )
    return tmp_path


def _sweep(folder: Path, *extra: str) -> int:
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        return main(["sweep", "scenario.py", "--grid", "grid.toml", *extra])
    finally:
        os.chdir(cwd)


@pytest.mark.long
def test_local_sweep_resume_rerun_and_report(sweep_dir: Path, capsys) -> None:
    rc = _sweep(sweep_dir, "-o", "results.csv", "--workers", "1")
    err = capsys.readouterr().err
    assert rc == 1, err  # one case runs into the limit: the sweep says so
    rows = {
        (r["distance"], r["machine.axis.1.positive_limit"]): r
        for r in read_rows(sweep_dir / "results.csv")
    }
    assert len(rows) == 6 and "6/6 cases" in err and "failures: 1" in err
    failed = [k for k, r in rows.items() if not r["ok"]]
    assert failed == [(8000, 5000)]
    assert rows[(8000, 9000)]["prf_pos"] == 8000 and rows[(3000, 5000)]["prf_pos"] == 3000
    bad = rows[(8000, 5000)]
    assert "rerun: gtecat sweep scenario.py --grid grid.toml --case " + bad["id"] in err
    assert not (sweep_dir / "results.csv.journal").exists()  # every row is in the file

    # a second run computes only what is missing: nothing, here (no cluster is started)
    assert _sweep(sweep_dir, "-o", "results.csv") == 1
    assert "0 to run" in capsys.readouterr().err
    # ... and after losing two rows, exactly those two
    lines = (sweep_dir / "results.csv").read_text().splitlines()
    (sweep_dir / "results.csv").write_text("\n".join(lines[:-2]) + "\n")
    assert _sweep(sweep_dir, "-o", "results.csv", "--workers", "1") == 1
    assert "2 to run" in capsys.readouterr().err
    assert sorted(r["id"] for r in read_rows(sweep_dir / "results.csv")) == sorted(
        r["id"] for r in rows.values()
    )

    # one case alone, by id, in this process: the same numbers as in the sweep
    assert _sweep(sweep_dir, "--case", bad["id"]) == 1
    alone = json.loads(capsys.readouterr().out)
    assert (alone["prf_pos"], alone["limit"], alone["ok"]) == (bad["prf_pos"], True, False)

    # the report: a page, the map and one histogram per measured value
    assert (
        main(["sweep", "report", str(sweep_dir / "results.csv"), "-o", str(sweep_dir / "rep")]) == 0
    )
    page = (sweep_dir / "rep" / "index.html").read_text()
    assert (sweep_dir / "rep" / "map.png").is_file() and (
        sweep_dir / "rep" / "value_prf_pos.png"
    ).is_file()
    assert f"--case {bad['id']}" in page and "6 cases, 5 passed, 1 failed" in page


def test_the_scenario_is_a_pytest_test_too(sweep_dir: Path) -> None:
    """One case of the same scenario, in this process (what a user's test calls)."""
    sys.path.insert(0, str(sweep_dir))
    try:
        from scenario import scenario  # the user's own module
    finally:
        sys.path.remove(str(sweep_dir))
        sys.modules.pop("scenario", None)
    values = run_one(scenario, sweep_dir / "grid.toml", distance=3000)
    assert values == {"prf_pos": 3000.0, "limit": False}
    with pytest.raises(AssertionError, match="returned ok=False"):
        run_one(scenario, sweep_dir / "grid.toml", distance=8000)


def _dask_cli(name: str) -> list[str]:
    exe = shutil.which("dask", path=str(Path(sys.executable).parent)) or shutil.which("dask")
    if exe is None:
        pytest.skip("needs the dask command (pip install 'gtecat[sweep]')")
    return [exe, name]


def _wait_for(path: Path, text: str, proc: subprocess.Popen, timeout_s: float = 60) -> None:
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if path.exists() and text in path.read_text(errors="replace"):
            return
        if proc.poll() is not None:
            raise AssertionError(f"{proc.args} ended: {path.read_text(errors='replace')}")
        time.sleep(0.05)  # waiting on another process's start-up, bounded
    raise AssertionError(
        f"{proc.args} not ready in {timeout_s} s: {path.read_text(errors='replace')}"
    )


@pytest.mark.long
def test_a_scheduler_with_two_workers_survives_a_killed_worker(sweep_dir: Path) -> None:
    """Every case exactly once in the results, though a worker died mid-sweep."""
    from dask.distributed import Client

    from gtecat.sweep.case import Job
    from gtecat.sweep.engine import run_cases
    from gtecat.sweep.grid import load_grid
    from gtecat.sweep.results import ResultsWriter

    (sweep_dir / "grid.toml").write_text(
        '[base]\neni = "manual_fig5_2"\nmachine = "m.toml"\n'
        "[grid]\ndistance = [1000, 2000, 3000, 4000]\nwait_ms = [300, 301, 302, 303, 304]\n"
    )
    procs: list[subprocess.Popen] = []
    logs = {n: (sweep_dir / f"{n}.log").open("w") for n in ("scheduler", "w1", "w2")}
    try:
        sched = subprocess.Popen(
            [*_dask_cli("scheduler"), "--host", "127.0.0.1", "--port", "0", "--no-dashboard"],
            stdout=logs["scheduler"],
            stderr=subprocess.STDOUT,
        )
        procs.append(sched)
        _wait_for(sweep_dir / "scheduler.log", "Scheduler at:", sched)
        text = (sweep_dir / "scheduler.log").read_text()
        addr = text.split("Scheduler at:")[1].split()[0]
        for n in ("w1", "w2"):
            procs.append(
                subprocess.Popen(
                    [
                        *_dask_cli("worker"),
                        addr,
                        "--nworkers",
                        "1",
                        "--nthreads",
                        "1",
                        "--no-dashboard",
                        "--name",
                        n,
                    ],
                    stdout=logs[n],
                    stderr=subprocess.STDOUT,
                )
            )
        grid = load_grid(sweep_dir / "grid.toml")
        cases = grid.cases()
        with Client(addr, timeout=30) as client:
            client.wait_for_workers(2, timeout=60)
            writer = ResultsWriter(sweep_dir / "r.parquet")
            killed = []

            def kill_one(row):
                if len(writer.rows) == 3 and not killed:
                    procs[1].send_signal(signal.SIGKILL)
                    killed.append(row)

            run_cases(
                client,
                Job.from_files(sweep_dir / "scenario.py", grid),
                cases,
                writer,
                on_row=kill_one,
            )
            writer.close()
        assert killed and procs[1].wait(timeout=10) == -signal.SIGKILL
        ids = [r["id"] for r in read_rows(sweep_dir / "r.parquet")]
        assert sorted(ids) == sorted(c.id for c in cases)  # each once, none lost
        assert all(r["ok"] for r in read_rows(sweep_dir / "r.parquet"))
    finally:
        for p in procs:
            p.kill()
            p.wait(timeout=10)
        for f in logs.values():
            f.close()
