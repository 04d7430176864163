"""Plot a coordinated-motion path and its vector speed for docs/coordinated_motion.md.

    python tools/plot_crd_path.py [docs/img/crd_path.png]

Runs the example of the page on the emulated bus (lockstep clock): two lines
with a look-ahead corner, a counter-clockwise arc by centre, a clockwise arc by
radius, a line back; samples GT_GetPrfPos and GT_GetCrdVel every cycle.
"""

from __future__ import annotations

import sys
from ctypes import byref, c_double, c_int32, c_short
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from gtecat import gt

ROOT = Path(__file__).resolve().parents[1]


def ok(rc: int) -> None:
    if rc:
        raise SystemExit(f"rc {rc}: {gt.GTE_GetLastError()}")


def run() -> tuple[list[float], list[float], list[float], list[int]]:
    ok(gt.GT_Open(eni=str(ROOT / "examples" / "manual_fig5_2.eni"), clock="lockstep", log=""))
    ok(gt.GT_InitEcatComm())
    ready = c_short()
    while not (gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1):
        gt.GTE_Wait(1)
    ok(gt.GT_StartEcatComm())
    for a in (1, 2):
        ok(gt.GT_AxisOn(a))
        ok(gt.GT_ZeroPos(a, 1))
    prm = gt.TCrdPrm()
    prm.dimension, prm.synVelMax, prm.synAccMax = 2, 100.0, 1.0
    prm.profile[0], prm.profile[1] = 1, 2
    ok(gt.GT_SetCrdPrm(1, byref(prm)))
    ok(gt.GT_InitLookAhead(1, 0, 5.0, 1.0, 16, None))
    ok(gt.GT_LnXY(1, 20_000, 0, 40.0, 0.5))
    ok(gt.GT_LnXY(1, 20_000, 10_000, 40.0, 0.5))
    ok(gt.GT_ArcXYC(1, 0, 10_000, -10_000, 0.0, 1, 30.0, 0.5))  # ccw half circle
    ok(gt.GT_ArcXYR(1, -10_000, 0, 10_000.0, 0, 30.0, 0.5))  # cw, short way
    ok(gt.GT_LnXY(1, 0, 0, 40.0, 0.5))
    ok(gt.GT_CrdStart(1, 0))
    xs, ys, vs, segs = [0.0], [0.0], [0.0], [0]
    run, seg = c_short(), c_int32()
    p, v = c_double(), c_double()
    while True:
        gt.GTE_Wait(1)
        gt.GT_GetPrfPos(1, byref(p))
        xs.append(p.value)
        gt.GT_GetPrfPos(2, byref(p))
        ys.append(p.value)
        gt.GT_GetCrdVel(1, byref(v))
        vs.append(v.value)
        gt.GT_CrdStatus(1, byref(run), byref(seg))
        segs.append(seg.value)
        if not run.value:
            break
    gt.GT_Close()
    return xs, ys, vs, segs


def main(argv: list[str]) -> int:
    out = Path(argv[1]) if len(argv) > 1 else ROOT / "docs" / "img" / "crd_path.png"
    xs, ys, vs, segs = run()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    sc = ax1.scatter(xs, ys, c=vs, s=2, cmap="viridis")
    ax1.set_aspect("equal")
    ax1.set_xlabel("X (pulse)")
    ax1.set_ylabel("Y (pulse)")
    ax1.set_title("path, one dot per 1 ms cycle")
    fig.colorbar(sc, ax=ax1, label="vector speed (pulse/ms)")
    ax2.plot(range(len(vs)), vs, lw=1)
    for k in range(1, len(segs)):
        if segs[k] != segs[k - 1]:
            ax2.axvline(k, color="grey", lw=0.5, ls=":")
    ax2.set_xlabel("time (ms)")
    ax2.set_ylabel("GT_GetCrdVel (pulse/ms)")
    ax2.set_title("vector speed; dotted: a segment ends")
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=110)
    print(f"{out}: {len(vs) - 1} ms, {segs[-1]} segments")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv))
