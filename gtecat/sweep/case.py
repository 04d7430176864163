"""One case of a sweep: a fresh controller in the lockstep clock, in OP, and the scenario.

This is all a worker runs; the engine (:mod:`gtecat.sweep.engine`) only distributes it.  The
scenario arrives as its source text (a worker on another machine has no copy of the file)
and is compiled once per worker process.  The ENI arrives as bytes for the same reason.
"""

from __future__ import annotations

import hashlib
import math
import shutil
import tempfile
import time
import traceback
import types
from collections.abc import Callable, Mapping
from ctypes import byref, c_short
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .grid import Case, Grid

Scenario = Callable[[Any, Case], Mapping[str, Any] | None]
#: the signals a failing case's trace keeps, per axis
TRACE_SIGNALS = ("prf", "enc", "err", "sw")


@dataclass(frozen=True)
class Job:
    """What a worker needs to run cases: picklable, self-contained."""

    scenario_name: str
    scenario_source: str
    eni_name: str
    eni_bytes: bytes
    machine: dict[str, Any]
    card: str | None = None
    keep_dir: str | None = None  #: where failing cases keep their traceback and trace

    @classmethod
    def from_files(cls, scenario: str | Path, grid: Grid, keep_dir: str | None = None) -> Job:
        path = Path(scenario)
        return cls(
            str(path),
            path.read_text(encoding="utf-8"),
            grid.eni,
            grid.eni_bytes,
            grid.machine,
            grid.card,
            keep_dir,
        )


_SCENARIOS: dict[str, Scenario] = {}
#: this process's own folder for the ENIs it was sent (removed when the process ends)
_ENI_DIR = tempfile.TemporaryDirectory(prefix="gtecat-sweep-")


def load_scenario(name: str, source: str) -> Scenario:
    """``scenario(gt, case)`` of a scenario file's source (compiled once per process)."""
    key = hashlib.sha256(source.encode()).hexdigest()
    if key not in _SCENARIOS:
        module = types.ModuleType("gtecat_scenario")
        module.__file__ = name
        exec(compile(source, name, "exec"), module.__dict__)
        fn = module.__dict__.get("scenario")
        if not callable(fn):
            raise ValueError(f"{name} defines no function scenario(gt, case)")
        _SCENARIOS[key] = fn
    return _SCENARIOS[key]


def _eni_file(job: Job) -> str:
    """The ENI as a file in this process's temp folder (written once per content)."""
    digest = hashlib.sha256(job.eni_bytes).hexdigest()[:16]
    path = Path(_ENI_DIR.name) / f"{digest}.eni"
    if not path.exists():
        path.write_bytes(job.eni_bytes)
    return str(path)


def bring_up(gt: Any, timeout_ms: int = 10_000) -> None:
    """Manual example 5-5: init, poll ready, start; raises with the GT reason."""
    if gt.GT_InitEcatComm() != 0:
        raise RuntimeError("GT_InitEcatComm: " + gt.GTE_GetLastError())
    status = c_short()
    for _ in range(timeout_ms):
        if gt.GT_IsEcatReady(byref(status)) == 0 and status.value == 1:
            break
        gt.GTE_Wait(1)
    else:
        raise RuntimeError(f"the bus did not reach OP in {timeout_ms} ms: {gt.GTE_GetLastError()}")
    if gt.GT_StartEcatComm() != 0:
        raise RuntimeError("GT_StartEcatComm: " + gt.GTE_GetLastError())


def run_case(job: Job, case: Case) -> dict[str, Any]:
    """Run ``case`` in a fresh controller; the result row (never raises)."""
    from .. import gt
    from ..drives.machine import machine_from_dict

    row: dict[str, Any] = {"id": case.id, "seed": case.seed, **case.params}
    t0 = time.perf_counter()
    folder = Path(tempfile.mkdtemp(prefix=f"gtecat-case-{case.id}-"))
    recorder = None
    try:
        scenario = load_scenario(job.scenario_name, job.scenario_source)
        machine = _machine(job, case)
        gt._core.close_all()
        options: dict[str, Any] = {
            "machine": machine_from_dict(machine, f"case {case.id}") if machine else None,
            "clock": "lockstep",
            "log": str(folder / "Gecat.log"),
            "mram": str(folder / "Gecat.mram"),
        }
        if job.card:
            options["card"] = job.card
        else:
            options["eni"] = _eni_file(job)
        if gt.GT_Open(**options) != 0:
            raise RuntimeError("GT_Open: " + gt.GTE_GetLastError())
        if not job.card:
            bring_up(gt)
        recorder = _recorder(gt) if job.keep_dir else None
        values = scenario(gt, case)
        if values is None:
            values = {}
        if not isinstance(values, Mapping):
            raise TypeError(f"scenario returned {type(values).__name__}, not a dict of values")
        values = dict(values)
        ok = bool(values.pop("ok", True))
        for key, value in values.items():
            row[key if key not in row else f"value.{key}"] = _plain(value)
        row["ok"] = ok
        row["error"] = "" if ok else "the scenario returned ok=False"
    except Exception:
        row["ok"] = False
        row["error"] = traceback.format_exc(limit=-8)
    finally:
        row["seconds"] = time.perf_counter() - t0
        if not row["ok"] and job.keep_dir:
            row["kept"] = _keep(job.keep_dir, case, row["error"], recorder)
        if recorder is not None:
            recorder.stop()
        gt._core.close_all()  # every card the scenario opened
        shutil.rmtree(folder, ignore_errors=True)
    return row


def _machine(job: Job, case: Case) -> dict[str, Any]:
    grid = Grid(Path(job.scenario_name), job.eni_name, job.eni_bytes, job.machine)
    return grid.machine_for(case)


def _recorder(gt: Any) -> Any:
    from ..controller.recorder import Recorder

    ctl = gt.GTE_Controller()
    axes = len(ctl.require_master().layout.axes) if ctl.master is not None else 0
    signals = [f"axis{a}.{s}" for a in range(1, axes + 1) for s in TRACE_SIGNALS]
    return Recorder(ctl, signals).start() if signals else None


def _keep(keep_dir: str, case: Case, error: str, recorder: Any) -> str:
    """A failing case's folder: its traceback (or reason) and its trace CSV."""
    folder = Path(keep_dir) / case.id
    try:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "error.txt").write_text(error, encoding="utf-8")
        if recorder is not None:
            recorder.to_csv(folder / "trace.csv")
    except OSError as e:
        return f"(not kept: {e.strerror})"
    return str(folder)


def _plain(value: Any) -> Any:
    """A value a results table can hold: numbers, bools and text; anything else as text."""
    if hasattr(value, "item") and callable(value.item):
        try:
            value = value.item()
        except (TypeError, ValueError):
            pass
    if isinstance(value, bool | int | str):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else str(value)
    return str(value)
