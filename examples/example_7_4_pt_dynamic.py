"""Manual example 7-4, "PT dynamic FIFO" (figure 7-9): a sine speed fed while it runs.

    python example_7_4_pt_dynamic.py [--plot pt_sine.png]

Axis 1 in PT mode, dynamic FIFO.  The speed is 50·sin(2πt/1 s) pulse/ms, cut into
16 ms NORMAL segments; each period ends with a STOP segment back at position 0,
and the program sends two periods (LOOP_TIMES).  One segment goes out per PLC
scan while GT_PtSpace reports room: the data fill FIFO1 then FIFO2, the motion
starts when both are full, and every time the controller has used up a FIFO it
clears it and the program refills it - 7.4.2 (4).  The times are computed in
seconds as the manual does (``ttime*1000``) and rounded to the ``long`` time GT_PtData takes,
as the conversion of the manual's LREAL expression to the DINT parameter does.
"""

# ruff: noqa: N815  (the PLC variables keep the manual's names)
from __future__ import annotations

import argparse
import math
import sys
from ctypes import byref, c_double, c_long, c_short
from dataclasses import dataclass
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
ENI = HERE / "manual_fig5_2.eni"
CONFIG = HERE / "test.cfg"
LOG: list[str] = []

# VAR CONSTANT
A = 50  # amplitude, pulse/ms
T = 1  # period, s
DELTA = 0.016  # segment time, s
LOOP_TIMES = 2
PI = 3.1415926


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


@dataclass
class PlcVars:
    """The VAR block of example 7-4."""

    xInitDone: bool = False
    rtn: int = 0
    Axis: int = 1
    xStart: bool = False
    xStarting: bool = False
    xStarted: bool = False
    space: int = 0
    pos: float = 0.0
    vel: float = 0.0
    velPre: float = 0.0
    ttime: float = 0.0  # seconds
    loop: int = 1
    lrPrfPos: float = 0.0
    lrPrfVel: float = 0.0
    dwAxisStatus: int = 0


def pt_start(v: PlcVars) -> None:
    v.rtn = gt.GT_PtStart(1 << (v.Axis - 1), 0)
    commandhandler("GT_PtStart", v.rtn)
    v.xStarted = True


def plc_prg(v: PlcVars) -> None:
    """One scan of example 7-4."""
    if not v.xInitDone:
        v.rtn = gt.GT_LoadConfig(str(CONFIG))  # alarms and limits off
        commandhandler("GT_LoadConfig", v.rtn)
        v.rtn = gt.GT_ClrSts(1, 8)
        commandhandler("GT_ClrSts", v.rtn)
        v.rtn = gt.GT_AxisOn(v.Axis)
        commandhandler("GT_AxisOn", v.rtn)
        v.xInitDone = True
    if v.xStart:
        v.rtn = gt.GT_ZeroPos(v.Axis, 1)
        commandhandler("GT_ZeroPos", v.rtn)
        v.rtn = gt.GT_PrfPt(v.Axis, gt.PT_MODE_DYNAMIC)  # PT mode, dynamic FIFO
        commandhandler("GT_PrfPt", v.rtn)
        v.rtn = gt.GT_PtClear(v.Axis, 0)
        commandhandler("GT_PtClear", v.rtn)
        v.pos = v.vel = v.velPre = 0.0
        v.ttime = 0.0
        v.loop = 1
        v.xStarting = True
        v.xStart = False
        v.xStarted = False
    if v.xStarting:
        space = c_short()
        v.rtn = gt.GT_PtSpace(v.Axis, byref(space), 0)
        v.space = space.value
        if v.space > 0:
            v.ttime += DELTA
            v.vel = A * math.sin(2 * PI / T * v.ttime)  # speed at the segment end
            v.pos += 1000 * (v.vel + v.velPre) * DELTA / 2  # displacement of the segment
            v.velPre = v.vel
            if v.ttime < v.loop * T:
                v.rtn = gt.GT_PtData(v.Axis, v.pos, round(v.ttime * 1000), gt.PT_SEGMENT_NORMAL, 0)
                commandhandler("GT_PtData", v.rtn)
            else:  # end of a period: back to 0 with a STOP segment
                v.rtn = gt.GT_PtData(v.Axis, 0, round(v.loop * T * 1000), gt.PT_SEGMENT_STOP, 0)
                commandhandler("GT_PtData", v.rtn)
                v.pos = 0.0
                v.ttime = v.loop * T
                v.velPre = 0.0
                v.loop += 1
                if v.loop > LOOP_TIMES:
                    if not v.xStarted:
                        pt_start(v)
                    v.xStarting = False
        elif not v.xStarted:  # both FIFOs full: start
            pt_start(v)
    sts = c_long()
    v.rtn = gt.GT_GetSts(v.Axis, byref(sts), 1, None)
    v.dwAxisStatus = sts.value
    pos, vel = c_double(), c_double()
    v.rtn = gt.GT_GetPrfPos(v.Axis, byref(pos), 1, None)
    v.rtn = gt.GT_GetPrfVel(v.Axis, byref(vel), 1, None)
    v.lrPrfPos, v.lrPrfVel = pos.value, vel.value


def bring_up(**options: object) -> None:
    options.setdefault("log", "")
    commandhandler("GT_Open", gt.GT_Open(eni=str(ENI), **options))
    commandhandler("GT_InitEcatComm", gt.GT_InitEcatComm())
    ready = c_short()
    for _ in range(10_000):
        if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
            break
        gt.GTE_Wait(1)
    commandhandler("GT_StartEcatComm", gt.GT_StartEcatComm())
    commandhandler("GT_Reset", gt.GT_Reset())


def run(max_scans: int = 4000, **options: object) -> dict[str, object]:
    """Init, raise xStart, one scan per ms until the motion has started and ended.

    ``t`` counts ms from the scan that called GT_PtStart; ``space`` is what the
    program read before each scan's push (-1 once it stopped sending).
    """
    LOG.clear()
    gt.GT_Close()
    bring_up(**options)
    try:
        v = PlcVars()
        plc_prg(v)  # init scan
        v.xStart = True
        t, pos, vel, space, pushing = [], [], [], [], []
        clock = c_long()
        t0 = None
        for _ in range(max_scans):
            plc_prg(v)
            gt.GT_GetClock(byref(clock))
            if t0 is None and v.xStarted:
                t0 = clock.value
            if t0 is not None:
                t.append(clock.value - t0)
                pos.append(v.lrPrfPos)
                vel.append(v.lrPrfVel)
                space.append(v.space if v.xStarting else -1)
                pushing.append(v.xStarting)
                if len(t) > 1 and not v.dwAxisStatus & (1 << 10):
                    break
            gt.GTE_Wait(1)  # one PLC scan
        return {
            "t": t,
            "pos": pos,
            "vel": vel,
            "space": space,
            "pushing": pushing,
            "errors": list(LOG),
        }
    finally:
        gt.GT_Close()


def plot(r: dict[str, object], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(8, 5))
    a1.plot(r["t"], r["vel"])
    a1.set_ylabel("planned velocity (pulse/ms)")
    a2.plot(r["t"], r["pos"])
    a2.set_ylabel("planned position (pulse)")
    a2.set_xlabel("time since GT_PtStart (ms)")
    fig.suptitle("example 7-4: PT dynamic FIFO, two sine periods (figure 7-9)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plot", help="write the velocity/position figure (PNG) here")
    args = ap.parse_args(argv)
    r = run()
    print(
        f"{r['t'][-1]} ms of motion, peak speed {max(r['vel']):.2f} pulse/ms, "
        f"ends at {r['pos'][-1]:g} pulses"
    )
    for line in r["errors"]:
        print("error:", line)
    if args.plot:
        plot(r, args.plot)
    return 0 if not r["errors"] and abs(r["pos"][-1]) < 1e-9 else 1


if __name__ == "__main__":
    sys.exit(main())
