"""Replay speed: a recorded 12-axis, 60-virtual-second session replayed against real time.

The session is an application's loop: bring-up, servo on, then every 10 ms of controller
time GT_GetSts on each of the 12 axes, a new Trap move on every axis that is at rest, and
one GT_GetPrfPos per axis every 100 ms.  It is recorded (gtecat.faults.record) and
replayed; the report gives the calls, the replay's wall and CPU time, and virtual/wall = how
many times faster than real time the replay runs (the bar: at least 50; virtual/CPU is the
same figure on a machine nobody else loads).

    python tools/bench_replay.py [--seconds 60] [--json]
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from ctypes import byref, c_double, c_long, c_short
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ENI = ROOT / "examples" / "twelve_axes.eni"


def session(gt, seconds: float) -> None:
    assert gt.GT_Open(eni=str(ENI), clock="auto", log="") == 0
    assert gt.GT_InitEcatComm() == 0
    st = c_short()
    while gt.GT_IsEcatReady(byref(st)) == 0 and st.value != 1:
        gt.GTE_Wait(1)
    gt.GT_StartEcatComm()
    gt.GT_Reset()
    n = 12
    for a in range(1, n + 1):
        gt.GT_AxisOn(a)
    prm = gt.TTrapPrm()
    prm.acc = prm.dec = 0.5
    sts, pos = c_long(), c_double()
    target = [0] * (n + 1)
    t_end = seconds * 1000
    clock = c_long()
    step = 0
    while True:
        gt.GT_GetClock(byref(clock))
        if clock.value >= t_end:
            break
        for a in range(1, n + 1):
            gt.GT_GetSts(a, byref(sts))
            if not sts.value & 0x400:  # at rest: the next move
                target[a] = 20_000 if target[a] <= 0 else -20_000
                gt.GT_PrfTrap(a)
                gt.GT_SetTrapPrm(a, byref(prm))
                gt.GT_SetPos(a, target[a])
                gt.GT_SetVel(a, 10 + a)
                gt.GT_Update(1 << (a - 1))
        if step % 10 == 0:
            for a in range(1, n + 1):
                gt.GT_GetPrfPos(a, byref(pos))
        step += 1
        gt.GTE_Wait(10)
    gt.GT_Close()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    from gtecat import gt
    from gtecat.faults.record import Recorder, replay

    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "session.gtrec"
        rec = Recorder(path).start()
        t0 = time.perf_counter()
        try:
            session(gt, args.seconds)
        finally:
            rec.stop()
        t_rec = time.perf_counter() - t0
        rec.write()
        t0, c0 = time.perf_counter(), time.process_time()
        n, div = replay(path)
        t_rep, c_rep = time.perf_counter() - t0, time.process_time() - c0
        size = path.stat().st_size
    out = {
        "virtual_s": args.seconds,
        "calls": n,
        "record_wall_s": round(t_rec, 3),
        "replay_wall_s": round(t_rep, 3),
        "replay_cpu_s": round(c_rep, 3),
        "times_real_time": round(args.seconds / t_rep, 1),
        "times_real_time_cpu": round(args.seconds / c_rep, 1),
        "file_bytes": size,
        "diverged": str(div) if div else None,
    }
    print(json.dumps(out) if args.json else "\n".join(f"{k}: {v}" for k, v in out.items()))
    return 0 if div is None else 1


if __name__ == "__main__":
    raise SystemExit(main())
