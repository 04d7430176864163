"""Cycle statistics a user can read: period, jitter percentiles, overruns, working counter.

The realtime clock (:class:`gtecat.master.clock.Clock`) records the wall-clock period
between cycle starts and counts overruns; a wire backend (pysoem) adds what it
saw on the bus: frame round trip, working-counter errors, lost frames,
recoveries.  :func:`cycle_stats` gathers both into one plain dict (what
``gt.GTE_GetCycleStats()`` returns and ``tools/bench_pysoem.py`` prints).

Jitter is the deviation of one period from the nominal cycle, ``|period -
cycle|``; percentiles use the nearest-rank method (no interpolation, so every
figure is a period that really happened).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True, slots=True)
class PeriodSummary:
    """Summary of measured cycle periods against the nominal cycle (all ns)."""

    samples: int
    nominal_ns: int
    mean_ns: float
    min_ns: int
    max_ns: int
    jitter_p50_ns: int
    jitter_p99_ns: int
    jitter_max_ns: int

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def nearest_rank(sorted_values: np.ndarray, q: float) -> int:
    """The ``q``-quantile (0..1) by nearest rank of an ascending array (0 when empty)."""
    n = len(sorted_values)
    if n == 0:
        return 0
    k = max(1, int(np.ceil(q * n)))
    return int(sorted_values[min(k, n) - 1])


def summarize_periods(periods_ns: Sequence[int] | np.ndarray, nominal_ns: int) -> PeriodSummary:
    """Mean/min/max period and jitter p50/p99/max of ``periods_ns`` around ``nominal_ns``."""
    if nominal_ns <= 0:
        raise ValueError("the nominal cycle must be positive")
    p = np.asarray(periods_ns, dtype=np.int64)
    if p.size == 0:
        return PeriodSummary(0, nominal_ns, 0.0, 0, 0, 0, 0, 0)
    jitter = np.sort(np.abs(p - nominal_ns))
    return PeriodSummary(
        samples=int(p.size),
        nominal_ns=int(nominal_ns),
        mean_ns=float(p.mean()),
        min_ns=int(p.min()),
        max_ns=int(p.max()),
        jitter_p50_ns=nearest_rank(jitter, 0.50),
        jitter_p99_ns=nearest_rank(jitter, 0.99),
        jitter_max_ns=int(jitter[-1]),
    )


def summarize_values(values_ns: Sequence[int] | np.ndarray) -> dict[str, int]:
    """p50/p99/max of a latency series (e.g. the frame round trip)."""
    v = np.sort(np.asarray(values_ns, dtype=np.int64))
    return {
        "samples": int(v.size),
        "p50_ns": nearest_rank(v, 0.50),
        "p99_ns": nearest_rank(v, 0.99),
        "max_ns": int(v[-1]) if v.size else 0,
    }


def cycle_stats(ctl: Any) -> dict[str, Any]:
    """Everything known about the cycle of controller ``ctl`` (any backend, any clock).

    Keys: ``clock`` (mode), ``cycle_ns``, ``cycles`` (run so far), ``overruns``,
    ``period`` (a :class:`PeriodSummary` dict; realtime clock only, else
    ``None``), ``wkc_errors`` (cycles whose working counter was not the
    expected one, as the master counted them), and ``bus`` (the backend's own
    figures when it has any: ``rtt`` round trip p50/p99/max, ``lost_frames``,
    ``recoveries``, ``checks``).
    """
    clock = ctl.clock
    stats = clock.stats
    periods = list(stats.periods_ns)
    out: dict[str, Any] = {
        "clock": clock.mode.value,
        "cycle_ns": int(clock.cycle_ns),
        "cycles": int(clock.cycles),
        "overruns": int(stats.overruns),
        "period": summarize_periods(periods, clock.cycle_ns).as_dict() if periods else None,
        "wkc_errors": int(ctl.master.wkc_errors) if ctl.master is not None else 0,
        "bus": None,
    }
    bus = getattr(ctl.backend, "stats", None)
    if bus is not None and hasattr(bus, "rtt_samples"):
        out["bus"] = {
            "backend": ctl.backend.name,
            "cycles": int(bus.cycles),
            "wkc_errors": int(bus.wkc_errors),
            "lost_frames": int(bus.lost_frames),
            "recoveries": int(bus.recoveries),
            "checks": int(bus.checks),
            "rtt": summarize_values(bus.rtt_samples()),
        }
    return out
