"""Wall time of a 10 s (virtual) homing run through the GT calls in the ``auto`` clock, as JSON.

    python tools/bench_homing_gt.py [--quick]

The whole stack: ``GT_*`` layer -> controller cycle -> emulated bus -> CiA-402 drive ->
homing component -> mechanics.  Bus ``examples/homing_probe.eni`` (2 drives), axis 1 of
example 5-2's machine started at 60500, method 3 with example 5-2's parameters (5000 /
3000 counts/s, 100000 counts/s²): 7.9 s to the switch at 100000, then 2.3 s back to the
index pulse at 93000, about 10.4 s of controller time.  Two ways of waiting:

* ``tight_poll``: ``do { GT_GetEcatHomingStatus(...) } while (status != 3)`` as C code
  would poll; every GT call costs 50 µs of virtual time in ``auto``, so about 20 calls
  run per 1 ms cycle;
* ``scan_1ms``: one status read per PLC scan (``GTE_Wait(1)`` between reads).

``wall_s`` counts from ``GT_StartEcatHoming`` to the status reading 3.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from ctypes import byref, c_double, c_long, c_short
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

ENI = ROOT / "examples" / "homing_probe.eni"
START = 60_500.0


def _machine():
    from gtecat.drives.machine import AxisMachine, MachineDescription

    return MachineDescription(
        {
            1: AxisMachine(
                position=START,
                counts_per_rev=10000,
                negative_limit=-400000,
                positive_limit=400000,
                home_switch=((100000.0, 400000.0),),
                index_offset=3000,
            )
        }
    )


def run(wait: str) -> dict[str, object]:
    """One homing run; ``wait`` is ``tight_poll`` or ``scan_1ms``."""
    from gtecat import gt

    t_open = time.perf_counter()
    gt.GT_Close()
    rc = gt.GT_Open(eni=str(ENI), machine=_machine(), clock="auto", log="")
    rc |= gt.GT_InitEcatComm()
    ready = c_short()
    while rc == 0 and not (gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1):
        pass
    rc |= gt.GT_StartEcatComm()
    rc |= gt.GT_AxisOn(1)
    rc |= gt.GT_SetHomingMode(1, 6)
    rc |= gt.GT_SetEcatHomingPrm(1, 3, 5000, 3000, 100000, 0, 0)
    if rc:
        raise SystemExit(f"setup failed: {gt.GTE_GetLastError()}")
    clock0, loop0 = c_long(), c_long()
    gt.GT_GetClock(byref(clock0), byref(loop0))
    t0 = time.perf_counter()
    if gt.GT_StartEcatHoming(1):
        raise SystemExit(f"GT_StartEcatHoming: {gt.GTE_GetLastError()}")
    status = c_short()
    calls = 0
    while True:
        gt.GT_GetEcatHomingStatus(1, byref(status))
        calls += 1
        if status.value & 1:
            break
        if wait == "scan_1ms":
            gt.GTE_Wait(1)
    wall = time.perf_counter() - t0
    clock1, loop1, machine = c_long(), c_long(), c_double()
    gt.GT_GetClock(byref(clock1), byref(loop1))
    gt.GTE_GetMachinePos(1, byref(machine))
    gt.GT_Close()
    virtual_s = (clock1.value - clock0.value) / 1000
    return {
        "status": status.value,
        "home_machine_position": round(machine.value, 3),
        "virtual_s": virtual_s,
        "cycles": loop1.value - loop0.value,
        "status_calls": calls,
        "wall_s": round(wall, 4),
        "virtual_per_wall": round(virtual_s / wall, 1),
        "wall_s_with_bring_up": round(time.perf_counter() - t_open, 4),
    }


def summary(quick: bool = False) -> dict[str, object]:
    waits = ("scan_1ms",) if quick else ("tight_poll", "scan_1ms")
    return {w: run(w) for w in waits}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="only the 1 ms scan variant")
    args = ap.parse_args(argv)
    print(json.dumps(summary(quick=args.quick), indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
