"""Manual example 7-1, "point-to-point motion" (figure 7-2), against the emulator.

    python example_7_1_trap.py [--plot trap.png]

Axis 1 moves 50000 pulses forward at 50 pulse/ms with acceleration 0.25 and
deceleration 0.125 pulse/ms² and a 25 ms smoothing time: 200 ms up, 600 ms at
speed, 400 ms down, each corner rounded over 25 ms - 1325 ms in all.
:func:`plc_prg` is the manual's program (its VAR block is :class:`PlcVars`),
called once per millisecond of controller time; the configuration file is
``test.cfg`` beside this script, in the vendor tool's format (every axis's alarm and
limit inputs "none", index -1; docs/config_file.md).
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
    """The VAR block of example 7-1."""

    xInitDone: bool = False
    rtn: int = 0
    Axis: int = 1
    xStart: bool = False
    lrPrfPos: float = 0.0
    dwAxisStatus: int = 0


def plc_prg(v: PlcVars) -> None:
    """One scan of example 7-1."""
    if not v.xInitDone:
        # configure the controller: the file switches every axis's alarm and limits off
        v.rtn = gt.GT_LoadConfig(str(CONFIG))
        commandhandler("GT_LoadConfig", v.rtn)
        v.rtn = gt.GT_ClrSts(1, 8)  # clear the axes' alarms and limits
        commandhandler("GT_ClrSts", v.rtn)
        v.rtn = gt.GT_AxisOn(v.Axis)  # servo on
        commandhandler("GT_AxisOn", v.rtn)
        v.xInitDone = True
    if v.xStart:
        v.rtn = gt.GT_ZeroPos(v.Axis, 1)  # positions to zero
        commandhandler("GT_ZeroPos", v.rtn)
        v.rtn = gt.GT_SetPrfPos(v.Axis, 0)  # the axis's planned position to zero
        commandhandler("GT_SetPrfPos", v.rtn)
        v.rtn = gt.GT_PrfTrap(v.Axis)  # point-to-point mode
        commandhandler("GT_PrfTrap", v.rtn)
        trap = gt.TTrapPrm()
        v.rtn = gt.GT_GetTrapPrm(v.Axis, byref(trap))  # read every parameter first
        commandhandler("GT_GetTrapPrm", v.rtn)
        trap.acc = 0.25
        trap.dec = 0.125
        trap.smoothTime = 25
        v.rtn = gt.GT_SetTrapPrm(v.Axis, byref(trap))
        commandhandler("GT_SetTrapPrm", v.rtn)
        v.rtn = gt.GT_SetPos(v.Axis, 50000)  # target position
        commandhandler("GT_SetPos", v.rtn)
        v.rtn = gt.GT_SetVel(v.Axis, 50)  # target speed
        commandhandler("GT_SetVel", v.rtn)
        v.rtn = gt.GT_Update(1 << (v.Axis - 1))  # start
        commandhandler("GT_Update", v.rtn)
        v.xStart = False
    sts = c_long()
    v.rtn = gt.GT_GetSts(v.Axis, byref(sts), 1, None)
    v.dwAxisStatus = sts.value
    pos = c_double()
    v.rtn = gt.GT_GetPrfPos(v.Axis, byref(pos), 1, None)
    v.lrPrfPos = pos.value


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
    """Init, start, then one scan per ms until bit 10 drops; the trace of every scan."""
    LOG.clear()
    gt.GT_Close()
    bring_up(**options)
    try:
        v = PlcVars()
        plc_prg(v)  # init scan
        v.xStart = True
        t, pos, vel, sts = [], [], [], []
        clock, t0 = c_long(), None
        for _ in range(max_scans):
            plc_prg(v)
            gt.GT_GetClock(byref(clock))
            t0 = clock.value if t0 is None else t0
            speed = c_double()
            gt.GT_GetPrfVel(v.Axis, byref(speed), 1, None)
            t.append(clock.value - t0)
            pos.append(v.lrPrfPos)
            vel.append(speed.value)
            sts.append(v.dwAxisStatus)
            if len(sts) > 1 and not v.dwAxisStatus & (1 << 10):
                break
            gt.GTE_Wait(1)  # one PLC scan
        return {"t": t, "pos": pos, "vel": vel, "sts": sts, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def plot(r: dict[str, object], path: str, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(8, 5))
    a1.plot(r["t"], r["vel"])
    a1.set_ylabel("planned velocity (pulse/ms)")
    a2.plot(r["t"], r["pos"])
    a2.set_ylabel("planned position (pulse)")
    a2.set_xlabel("controller time (ms)")
    fig.suptitle(title)
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
        plot(r, args.plot, "example 7-1: Trap, smoothTime 25 ms (figure 7-2)")
    return 0 if not r["errors"] and r["pos"][-1] == 50000 else 1


if __name__ == "__main__":
    sys.exit(main())
