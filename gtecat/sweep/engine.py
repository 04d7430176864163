"""Run a sweep's cases on Dask distributed: an embedded LocalCluster, or a running scheduler.

Dask, not a pool of our own: it already does what a sweep needs and a home-made pool would
get wrong - work stealing, a worker that dies has its cases run again elsewhere (each case's
result arrives exactly once, by its key), a cluster of many machines behind one address.
Each case is one task keyed by its id; the job (scenario source, ENI bytes, machine) is
scattered once to every worker, not sent with each case.
"""

from __future__ import annotations

import logging
import os
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, TextIO

from ..errors import ParameterError
from .case import Job, run_case
from .grid import Case
from .results import ResultsWriter


@dataclass
class Progress:
    """Cases done, cases per second and failures so far, drawn on one terminal line."""

    total: int
    stream: TextIO = field(default_factory=lambda: sys.stderr)
    done: int = 0
    failed: int = 0
    t0: float = field(default_factory=time.monotonic)
    _last: float = 0.0

    def update(self, ok: bool) -> None:
        self.done += 1
        self.failed += 0 if ok else 1
        now = time.monotonic()
        tty = self.stream.isatty()
        if self.done == self.total or now - self._last >= (0.2 if tty else 5.0):
            self._last = now
            self.draw(end="" if tty and self.done < self.total else "\n", tty=tty)

    def rate(self) -> float:
        return self.done / max(time.monotonic() - self.t0, 1e-9)

    def draw(self, end: str, tty: bool) -> None:
        width = 30
        filled = int(width * self.done / max(self.total, 1))
        bar = "#" * filled + "." * (width - filled)
        text = (
            f"[{bar}] {self.done}/{self.total} cases  {self.rate():.1f} cases/s  "
            f"failures: {self.failed}"
        )
        self.stream.write(("\r" if tty else "") + text + end)
        self.stream.flush()


def client_for(scheduler: str | None, workers: int | None) -> Any:
    """A Dask client: of the scheduler at ``scheduler``, else of a new LocalCluster."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise ParameterError(
            "sweeps run on Dask distributed: pip install 'gtecat[sweep]' "
            "(dask[distributed] and pyarrow)"
        ) from None
    if scheduler:
        try:
            return Client(scheduler, timeout=10)
        except (OSError, TimeoutError) as e:
            raise ParameterError(f"cannot reach the Dask scheduler at {scheduler}: {e}") from None
    n = workers or os.cpu_count() or 1
    cluster = LocalCluster(
        n_workers=n,
        threads_per_worker=1,  # a case is CPU work in one thread; one process per CPU
        processes=True,
        dashboard_address=None,
        silence_logs=logging.ERROR,
    )
    return Client(cluster)


def run_cases(
    client: Any,
    job: Job,
    cases: Sequence[Case],
    writer: ResultsWriter,
    progress: Progress | None = None,
    on_row: Callable[[dict[str, Any]], None] | None = None,
) -> None:
    """Submit every case, write each row as it arrives; Ctrl-C leaves what was written."""
    from dask.distributed import as_completed

    if not cases:
        return
    shared = client.scatter(job, broadcast=True, hash=False)
    futures = {
        client.submit(run_case, shared, case, key=f"gtecat-case-{case.id}", retries=0): case
        for case in cases
    }
    try:
        for future in as_completed(futures):
            case = futures[future]
            try:
                row = future.result()
            except Exception as e:  # the task itself never raises: its worker died, again and again
                row = {
                    "id": case.id,
                    "seed": case.seed,
                    **case.params,
                    "ok": False,
                    "error": f"the case could not be run: {type(e).__name__}: {e}",
                }
            writer.add(row)
            if progress is not None:
                progress.update(bool(row.get("ok")))
            if on_row is not None:
                on_row(row)
    finally:
        for future in futures:
            future.release()
