"""Buses whose application streams calls into moving axes: the figures
``rtf_64_axes_pt_dynamic`` and ``rtf_64_axes_move_absolute`` of ``tools/bench.py --targets``.

* ``pt_dynamic``: every axis in PT with dynamic FIFOs (``GT_PrfPt(a, PT_MODE_DYNAMIC)``), a
  ramp of 10 ms segments pushed until the FIFOs are full, ``GT_PtStart``; then every 20 ms,
  per axis, ``GT_PtSpace`` and a ``GT_PtData`` per free slot (64 axes: about 6,400 points and
  3,200 space reads a second).
* ``move_absolute``: every 20 ms a ``GT_MoveAbsolute`` to a new target on every axis (the
  last one's opposite, 20 pulse/ms, 0.5 pulse/ms²): a single-call Trap move, as a PLC
  program gives it.

Controller milliseconds per wall millisecond (``rtf``) and per CPU millisecond of this
process (``rtf_cpu``), the calls included; the fastest of ``repeat`` windows.
"""

from __future__ import annotations

import tempfile
import time
from ctypes import byref, c_short
from pathlib import Path
from typing import Any

from tools.bench_scaling import WARM_UP_MS, _clock, _gt, bring_up, core_axis, gtn
from tools.gen_axes_eni import write_axes_eni

#: how often the application calls, controller ms
POLL_MS = 20
#: the ramp the PT streams run (points of 10 ms; there and back)
PT_HALF = 200


def _pt_value(k: int) -> float:
    j = k % (2 * PT_HALF)
    return 20000.0 * (j if j <= PT_HALF else 2 * PT_HALF - j) / PT_HALF


def _pt_dynamic(n: int) -> Any:
    """Start every axis's stream; the poll that refills them."""
    gt = _gt()
    space = c_short()
    pushed = dict.fromkeys(range(1, n + 1), 0)

    def refill() -> None:
        for a in range(1, n + 1):
            gtn("PtSpace", a, byref(space), 0)
            for _ in range(space.value):
                pushed[a] += 1
                k = pushed[a]
                gtn("PtData", a, _pt_value(k), 10 * k, gt.PT_SEGMENT_NORMAL, 0)

    for a in range(1, n + 1):
        gtn("PrfPt", a, gt.PT_MODE_DYNAMIC)
        gtn("PtClear", a, 0)
    refill()
    masks: dict[int, int] = {}
    for a in range(1, n + 1):
        core, local = core_axis(a)
        masks[core] = masks.get(core, 0) | 1 << (local - 1)
    for core, mask in sorted(masks.items()):
        rc = gt.GTN_PtStart(core, mask, 0)
        if rc:
            raise RuntimeError(f"GTN_PtStart({core}): {rc} {gt.GTE_GetLastError()}")
    return refill


def _move_absolute(n: int) -> Any:
    gt = _gt()
    prm = gt.TMoveAbsolutePrm()
    sign = [1]

    def retarget() -> None:
        sign[0] = -sign[0]
        for a in range(1, n + 1):
            prm.pos, prm.vel, prm.acc, prm.percent = sign[0] * 200_000, 20.0, 0.5, 0
            gtn("MoveAbsolute", a, byref(prm))

    retarget()
    return retarget


STREAMS = {"pt_dynamic": _pt_dynamic, "move_absolute": _move_absolute}


def run_stream(
    n: int, kind: str, seconds: float = 1.5, repeat: int = 3, bank: str | None = None
) -> dict[str, Any]:
    """``n`` generated axes streaming ``kind`` (:data:`STREAMS`); the figures."""
    gt = _gt()
    with tempfile.TemporaryDirectory() as tmp:
        eni = write_axes_eni(n, Path(tmp) / f"axes{n}.eni")
        try:
            bring_up(eni, n, bank)
            for a in range(1, n + 1):
                gtn("AxisOn", a)
            gt.GTE_Wait(WARM_UP_MS)
            poll = STREAMS[kind](n)
            gt.GTE_Wait(WARM_UP_MS)
            window = seconds / max(1, repeat)
            best = (0.0, 0.0)
            for _ in range(max(1, repeat)):
                ms0, _ = _clock()
                t0, c0 = time.perf_counter(), time.process_time()
                while time.perf_counter() - t0 < window:
                    gt.GTE_Wait(POLL_MS)
                    poll()
                el = time.perf_counter() - t0
                cpu = max(time.process_time() - c0, 1e-9)
                ms1, _ = _clock()
                if (ms1 - ms0) / el > best[0]:
                    best = ((ms1 - ms0) / el / 1000, (ms1 - ms0) / cpu / 1000)
            bank_obj = gt.GTE_Controller().bank
            streamed = bank_obj.streamed_calls if bank_obj is not None else 0
        finally:
            gt.GT_Close()
    return {
        "rtf": round(best[0], 3),
        "rtf_cpu": round(best[1], 3),
        "poll_ms": POLL_MS,
        "calls_on_claimed_rows": streamed,
    }
