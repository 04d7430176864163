"""Manual example 7-3, "PT static FIFO" (table 7-5, figure 7-8), against the emulator.

    python example_7_3_pt.py [--plot pt.png]

Axis 1 in PT mode, static FIFO: three NORMAL segments ending at (1024 pulse,
1024 ms), (3072, 2048), (4096, 3072) - positions and times are points measured
from the start, not lengths (7.4.2 note).  The velocity rises linearly to
2 pulse/ms (2·1024/1024), stays there (2·2048/1024 - 2) and falls back to 0
(2·1024/1024 - 2): the trapezoid of figure 7-8.  :func:`plc_prg` is the
manual's program (its VAR block is :class:`PlcVars`), one scan per millisecond.
"""

# ruff: noqa: N815  (the PLC variables keep the manual's names)
from __future__ import annotations

import argparse
import sys
from ctypes import byref, c_double, c_long, c_short
from dataclasses import dataclass
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
ENI = HERE / "manual_fig5_2.eni"
CONFIG = HERE / "test.cfg"
LOG: list[str] = []


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


@dataclass
class PlcVars:
    """The VAR block of example 7-3."""

    xInitDone: bool = False
    rtn: int = 0
    Axis: int = 1
    xStart: bool = False
    space: int = 0
    pos: float = 0.0
    ttime: int = 0
    lrPrfPos: float = 0.0
    lrPrfVel: float = 0.0
    dwAxisStatus: int = 0


def push_if_space(v: PlcVars, dpos: float, dtime: int) -> None:
    """``GT_PtSpace``; if there is room, the next point (pos, ttime advanced) with GT_PtData."""
    space = c_short()
    v.rtn = gt.GT_PtSpace(v.Axis, byref(space), 0)
    commandhandler("GT_PtSpace", v.rtn)
    v.space = space.value
    if v.space > 0:
        v.pos += dpos
        v.ttime += dtime
        v.rtn = gt.GT_PtData(v.Axis, v.pos, v.ttime, gt.PT_SEGMENT_NORMAL, 0)
        commandhandler("GT_PtData", v.rtn)


def plc_prg(v: PlcVars) -> None:
    """One scan of example 7-3."""
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
        v.rtn = gt.GT_PrfPt(v.Axis, gt.PT_MODE_STATIC)  # PT mode, static FIFO
        commandhandler("GT_PrfPt", v.rtn)
        v.rtn = gt.GT_PtClear(v.Axis, 0)  # empty FIFO1
        commandhandler("GT_PtClear", v.rtn)
        v.pos, v.ttime = 0.0, 0
        push_if_space(v, 1024, 1024)  # (1024, 1024)
        push_if_space(v, 2048, 1024)  # (3072, 2048)
        push_if_space(v, 1024, 1024)  # (4096, 3072)
        v.rtn = gt.GT_PtStart(1 << (v.Axis - 1), 0)  # FIFO1
        commandhandler("GT_PtStart", v.rtn)
        v.xStart = False
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


def run(max_scans: int = 5000, **options: object) -> dict[str, object]:
    """Init, start, then one scan per ms until bit 10 drops; the trace after each scan's ms."""
    LOG.clear()
    gt.GT_Close()
    bring_up(**options)
    try:
        v = PlcVars()
        plc_prg(v)  # init scan
        v.xStart = True
        plc_prg(v)  # start scan: GT_PtStart
        t, pos, vel, sts = [], [], [], []
        clock, t0 = c_long(), None
        gt.GT_GetClock(byref(clock))
        t0 = clock.value
        for _ in range(max_scans):
            gt.GTE_Wait(1)  # one PLC scan
            plc_prg(v)
            gt.GT_GetClock(byref(clock))
            t.append(clock.value - t0)
            pos.append(v.lrPrfPos)
            vel.append(v.lrPrfVel)
            sts.append(v.dwAxisStatus)
            if not v.dwAxisStatus & (1 << 10):
                break
        return {"t": t, "pos": pos, "vel": vel, "sts": sts, "errors": list(LOG)}
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
    fig.suptitle("example 7-3: PT static FIFO, three NORMAL segments (figure 7-8)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plot", help="write the velocity/position figure (PNG) here")
    args = ap.parse_args(argv)
    r = run()
    print(
        f"moved to {r['pos'][-1]:g} pulses in {r['t'][-1]} ms, peak speed "
        f"{max(r['vel']):g} pulse/ms"
    )
    for line in r["errors"]:
        print("error:", line)
    if args.plot:
        plot(r, args.plot)
    return 0 if not r["errors"] and r["pos"][-1] == 4096 else 1


if __name__ == "__main__":
    sys.exit(main())
