"""Manual example 11-2, "in-position detection" (figure 11-2): Y starts when X is in position.

    python example_11_2_in_position.py [--plot inpos.png]

Both axes get an in-position band of 20 pulses held 5 x 250 µs (GT_SetAxisBand).
X moves to 10000 (vel 10 pulse/ms, acc 1, dec 0.5 pulse/ms²); the program starts
Y toward 20000 in the first scan that sees X's in-position flag (GT_GetSts bit
11) - set once X's profile stands and the following error has stayed within the
band for the hold time.  :func:`plc_prg` is the manual's program, one scan per
millisecond; the configuration file is ``servo.cfg`` beside this script.
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
CONFIG = HERE / "servo.cfg"
LOG: list[str] = []
AXIS_X = 1
AXIS_Y = 2
MOVING, ARRIVED = 1 << 10, 1 << 11


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


@dataclass
class PlcVars:
    """The VAR block of example 11-2 (``pid: TPid`` is declared there but not used)."""

    xInitDone: bool = False
    rtn: int = 0
    xStart: bool = False
    xStarted_X: bool = False
    xStarted_Y: bool = False
    posX: int = 10000
    PosY: int = 20000
    lrPrfPosX: float = 0.0
    lrPrfVelX: float = 0.0
    lrPrfPosY: float = 0.0
    lrPrfVelY: float = 0.0
    stsX: int = 0
    stsY: int = 0


def _trap(axis: int) -> None:
    v_rtn = gt.GT_PrfTrap(axis)
    commandhandler("GT_PrfTrap", v_rtn)
    trap = gt.TTrapPrm()
    commandhandler("GT_GetTrapPrm", gt.GT_GetTrapPrm(axis, byref(trap)))
    trap.acc = 1
    trap.dec = 0.5
    commandhandler("GT_SetTrapPrm", gt.GT_SetTrapPrm(axis, byref(trap)))
    commandhandler("GT_SetVel", gt.GT_SetVel(axis, 10))


def plc_prg(v: PlcVars) -> None:
    """One scan of example 11-2."""
    if not v.xInitDone:
        v.rtn = gt.GT_LoadConfig(str(CONFIG))  # the controller as a servo controller
        commandhandler("GT_LoadConfig", v.rtn)
        v.rtn = gt.GT_ClrSts(1, 8)
        commandhandler("GT_ClrSts", v.rtn)
        commandhandler("GT_AxisOn", gt.GT_AxisOn(AXIS_X))
        commandhandler("GT_AxisOn", gt.GT_AxisOn(AXIS_Y))
        commandhandler("GT_ZeroPos", gt.GT_ZeroPos(AXIS_X, 1))  # positions to zero
        commandhandler("GT_ZeroPos", gt.GT_ZeroPos(AXIS_Y, 1))
        commandhandler("GT_SetAxisBand", gt.GT_SetAxisBand(AXIS_X, 20, 5))  # X's band
        commandhandler("GT_SetAxisBand", gt.GT_SetAxisBand(AXIS_Y, 20, 5))  # Y's band
        v.xInitDone = True
        v.xStarted_X = False
        v.xStarted_Y = False
    if v.xStart:
        _trap(AXIS_X)  # X: Trap, acc 1, dec 0.5, speed 10
        _trap(AXIS_Y)  # Y: the same
        commandhandler("GT_SetPos", gt.GT_SetPos(AXIS_X, v.posX))
        commandhandler("GT_Update", gt.GT_Update(1 << (AXIS_X - 1)))  # start X
        v.xStarted_X = True
        v.xStarted_Y = False
        v.xStart = False
    # wait for X in its band (stsX is the status read at the end of the previous scan)
    if v.xStarted_X and v.stsX & ARRIVED and not v.xStarted_Y:
        commandhandler("GT_SetPos", gt.GT_SetPos(AXIS_Y, v.PosY))
        commandhandler("GT_Update", gt.GT_Update(1 << (AXIS_Y - 1)))  # start Y
        v.xStarted_Y = True
    sts, pos, vel = c_long(), c_double(), c_double()
    gt.GT_GetSts(AXIS_X, byref(sts), 1, None)
    v.stsX = sts.value
    gt.GT_GetPrfPos(AXIS_X, byref(pos), 1, None)
    gt.GT_GetPrfVel(AXIS_X, byref(vel), 1, None)
    v.lrPrfPosX, v.lrPrfVelX = pos.value, vel.value
    gt.GT_GetSts(AXIS_Y, byref(sts), 1, None)
    v.stsY = sts.value
    gt.GT_GetPrfPos(AXIS_Y, byref(pos), 1, None)
    gt.GT_GetPrfVel(AXIS_Y, byref(vel), 1, None)
    v.lrPrfPosY, v.lrPrfVelY = pos.value, vel.value


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


def run(max_scans: int = 10_000, **options: object) -> dict[str, object]:
    """Init, start X, Y after X's in-position flag, until Y is in position too."""
    LOG.clear()
    gt.GT_Close()
    bring_up(**options)
    try:
        v = PlcVars()
        plc_prg(v)
        v.xStart = True
        keys = ("t", "posX", "velX", "stsX", "posY", "velY", "stsY")
        tr: dict[str, list] = {k: [] for k in keys}
        clock, t0 = c_long(), None
        y_started_scan = None
        for k in range(max_scans):
            was = v.xStarted_Y
            plc_prg(v)
            if v.xStarted_Y and not was:
                y_started_scan = k
            gt.GT_GetClock(byref(clock))
            t0 = clock.value if t0 is None else t0
            for key, value in zip(
                keys,
                (
                    clock.value - t0,
                    v.lrPrfPosX,
                    v.lrPrfVelX,
                    v.stsX,
                    v.lrPrfPosY,
                    v.lrPrfVelY,
                    v.stsY,
                ),
                strict=True,
            ):
                tr[key].append(value)
            if v.xStarted_Y and v.stsY & ARRIVED:
                break
            gt.GTE_Wait(1)
        return {**tr, "y_started_scan": y_started_scan, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def plot(r: dict[str, object], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(8, 4.5))
    a1.plot(r["t"], r["velX"], label="X")
    a1.plot(r["t"], r["velY"], label="Y")
    a1.set_ylabel("planned velocity (pulse/ms)")
    a1.legend()
    a2.step(r["t"], [bool(s & ARRIVED) for s in r["stsX"]], where="post", label="X bit 11")
    a2.step(r["t"], [bool(s & ARRIVED) for s in r["stsY"]], where="post", label="Y bit 11")
    a2.set_ylabel("in position")
    a2.set_xlabel("controller time (ms)")
    a2.legend()
    fig.suptitle("example 11-2: Y starts when X is in position (figure 11-2)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plot", help="write the velocity / in-position figure (PNG) here")
    args = ap.parse_args(argv)
    r = run()
    k = r["y_started_scan"]
    print(
        f"X reached {r['posX'][-1]:g}; Y started at {r['t'][k] if k is not None else None} ms "
        f"and reached {r['posY'][-1]:g} (in position at {r['t'][-1]} ms)"
    )
    for line in r["errors"]:
        print("error:", line)
    if args.plot:
        plot(r, args.plot)
    return 0 if not r["errors"] and r["posY"][-1] == 20000 else 1


if __name__ == "__main__":
    sys.exit(main())
