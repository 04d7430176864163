"""Cost of the drive-side homing and touch-probe components, printed as JSON.

    python tools/bench_homing.py [--quick]

``homing_10s``: one homing run (method 7 from the right of the cam: out to the
positive limit, back through the cam, index search, return) that takes about 10 s of
virtual time at 1 kHz, with :class:`gtecat.drives.homing.Homing` and a kinematic axis (the
actual position is last cycle's demand).  ``all_methods``: every supported method
once on the same machine.  ``touch_probe_us_per_step``: both probes enabled in
continuous mode on both edges, axis crossing marks.  Only the components are timed,
not the bus or the CiA-402 state machine.
"""

from __future__ import annotations

import argparse
import json
import time

from gtecat.drives.homing import SUPPORTED_METHODS, Homing, HomingParams
from gtecat.drives.machine import AxisMachine
from gtecat.drives.touch_probe import TouchProbe

MACHINE = AxisMachine(
    counts_per_rev=10000,
    negative_limit=-100_000,
    positive_limit=100_000,
    home_switch=((24_500, 47_000),),
    index_offset=1_300,
    probe1=tuple((float(x), x + 250.5) for x in range(-90_000, 90_000, 1_000)),
    probe2=tuple((x + 0.3, x + 0.9) for x in range(-90_000, 90_000, 3_000)),
)
DT = 0.001


def _run(method: int, start: float, speed: float) -> tuple[int, float, Homing]:
    p = HomingParams(method, speed, speed / 5.0, 200_000.0, 0)
    h = Homing(p, MACHINE, start)
    pos = start
    n = 0
    t0 = time.perf_counter()
    while not h.done and n < 600_000:
        pos = h.step(DT, pos)
        n += 1
    return n, time.perf_counter() - t0, h


def _probe(cycles: int) -> float:
    tp = TouchProbe(MACHINE)
    tp.write_function(0x3333)  # both probes, continuous, both edges
    pos, v = -80_000.0, 97.3
    t_ns = 0
    t0 = time.perf_counter()
    for _ in range(cycles):
        t_ns += 1_000_000
        tp.step(pos, pos + v, pos, pos + v, t_ns, 1_000_000)
        pos += v
    return (time.perf_counter() - t0) / cycles * 1e6


def summary(quick: bool = False) -> dict[str, object]:
    n, wall, h = _run(7, 70_000.0, 12_000.0)
    out: dict[str, object] = {
        "homing_10s": {
            "method": 7,
            "virtual_s": round(n * DT, 3),
            "cycles": n,
            "wall_s": round(wall, 4),
            "us_per_step": round(wall / n * 1e6, 3),
            "home": h.home_machine_position,
        }
    }
    total_n, total_wall, homed = 0, 0.0, 0
    for m in sorted(SUPPORTED_METHODS):
        start = 60_000.0 if m not in (1, 2, 17, 18) else 0.0
        k, w, hm = _run(m, start, 25_000.0)
        total_n += k
        total_wall += w
        homed += hm.attained
    out["all_methods"] = {
        "methods": len(SUPPORTED_METHODS),
        "homed": homed,  # 3/4/19/20 end in a (correct) error: start beyond a finite switch
        "cycles": total_n,
        "wall_s": round(total_wall, 4),
        "us_per_step": round(total_wall / max(total_n, 1) * 1e6, 3),
    }
    out["touch_probe_us_per_step"] = round(_probe(20_000 if quick else 200_000), 3)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer probe cycles")
    args = ap.parse_args(argv)
    print(json.dumps(summary(quick=args.quick), indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
