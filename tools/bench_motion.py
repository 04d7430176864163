"""Cost of one planner step (µs), printed as JSON: ``python tools/bench_motion.py``.

Each case runs a whole move (or a fixed number of jog cycles) and divides the
wall time by the number of ``step()`` calls.  Planner ``step()`` runs once per
axis per controller cycle, so 12 axes at 1 kHz need well under 80 µs each
for 3x real time.
"""

from __future__ import annotations

import argparse
import json
import time

from gtecat.controller.motion import JogParams, JogPlanner, TrapParams, TrapPlanner


def _trap(smooth_time: int, repeat: int) -> tuple[float, int]:
    tp = TrapPlanner(1.0)
    prm = TrapParams(0.25, 0.125, 0.0, smooth_time)
    n = 0
    t0 = time.perf_counter()
    for _ in range(repeat):
        tp.start(0.0, 50000, 50.0, prm)  # example 7-1: 1300 ms (+ smoothTime)
        while not tp.done:
            tp.step()
            n += 1
    return time.perf_counter() - t0, n


def _jog(smooth: float, cycles: int) -> tuple[float, int]:
    jp = JogPlanner(1.0)
    jp.start(0.0, 100.0, JogParams(0.0625, 0.0625, smooth))  # example 7-2
    t0 = time.perf_counter()
    for k in range(cycles):
        if k == cycles // 2:
            jp.update(50.0)
        jp.step()
    return time.perf_counter() - t0, cycles


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=20, help="moves per Trap case")
    args = ap.parse_args(argv)
    cases = {
        "trap_us_per_step": _trap(0, args.repeat),
        "trap_smooth25_us_per_step": _trap(25, args.repeat),
        "jog_us_per_step": _jog(0.0, 1300 * args.repeat),
        "jog_smooth0.9_us_per_step": _jog(0.9, 1300 * args.repeat),
    }
    result: dict[str, float | int] = {k: round(dt / n * 1e6, 3) for k, (dt, n) in cases.items()}
    result["steps_per_case"] = cases["trap_us_per_step"][1]
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
