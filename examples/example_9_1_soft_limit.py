"""Manual example 9-1, "soft limits" (figure 9-2): the motion stops at the positive soft limit.

    python example_9_1_soft_limit.py [--plot softlimit.png]

Axis 1's soft limits are +20000 / -20000.  A Trap move toward 1000000 (50 pulse/ms,
acc = dec = 0.125 pulse/ms², smoothTime 25 ms) passes +20000: in that cycle the
positive limit flag (GT_GetSts bit 5) rises and the motion stops with the
abrupt-stop deceleration (1000 pulse/ms², 9.2.2), within a cycle's travel
(here about 26 pulses) past the limit.  :func:`plc_prg` is the manual's program,
one scan per millisecond.
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
POSITIVE_LIMIT_FLAG = 1 << 5


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


@dataclass
class PlcVars:
    """The VAR block of example 9-1."""

    xInitDone: bool = False
    rtn: int = 0
    Axis: int = 1
    xStart: bool = False
    lrPrfPos: float = 0.0
    dwAxisStatus: int = 0


def plc_prg(v: PlcVars) -> None:
    """One scan of example 9-1."""
    if not v.xInitDone:
        v.rtn = gt.GT_LoadConfig(str(CONFIG))
        commandhandler("GT_LoadConfig", v.rtn)
        v.rtn = gt.GT_ClrSts(1, 8)  # clear the axis status
        commandhandler("GT_ClrSts", v.rtn)
        v.rtn = gt.GT_SetSoftLimit(v.Axis, 20000, -20000)  # soft limits
        commandhandler("GT_SetSoftLimit", v.rtn)
        v.rtn = gt.GT_AxisOn(v.Axis)
        commandhandler("GT_AxisOn", v.rtn)
        v.xInitDone = True
    if v.xStart:
        v.rtn = gt.GT_PrfTrap(v.Axis)
        commandhandler("GT_PrfTrap", v.rtn)
        trap = gt.TTrapPrm()
        v.rtn = gt.GT_GetTrapPrm(v.Axis, byref(trap))
        commandhandler("GT_GetTrapPrm", v.rtn)
        trap.acc = 0.125
        trap.dec = 0.125
        trap.smoothTime = 25
        v.rtn = gt.GT_SetTrapPrm(v.Axis, byref(trap))
        commandhandler("GT_SetTrapPrm", v.rtn)
        v.rtn = gt.GT_SetPos(v.Axis, 1000000)
        commandhandler("GT_SetPos", v.rtn)
        v.rtn = gt.GT_SetVel(v.Axis, 50)
        commandhandler("GT_SetVel", v.rtn)
        v.rtn = gt.GT_Update(1 << (v.Axis - 1))
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


def run(max_scans: int = 5000, tail_ms: int = 100, **options: object) -> dict[str, object]:
    """Init, start, one scan per ms until the profile stands (and ``tail_ms`` more)."""
    LOG.clear()
    gt.GT_Close()
    bring_up(**options)
    try:
        v = PlcVars()
        plc_prg(v)
        v.xStart = True
        t, pos, sts = [], [], []
        clock, t0 = c_long(), None
        stopped = None
        for k in range(max_scans):
            plc_prg(v)
            gt.GT_GetClock(byref(clock))
            t0 = clock.value if t0 is None else t0
            t.append(clock.value - t0)
            pos.append(v.lrPrfPos)
            sts.append(v.dwAxisStatus)
            if stopped is None and k > 0 and not v.dwAxisStatus & (1 << 10):
                stopped = k
            if stopped is not None and k >= stopped + tail_ms:
                break
            gt.GTE_Wait(1)
        return {"t": t, "pos": pos, "sts": sts, "stopped": stopped, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def plot(r: dict[str, object], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(8, 4.5))
    a1.plot(r["t"], r["pos"])
    a1.axhline(20000, color="tab:red", lw=0.8, label="positive soft limit")
    a1.set_ylabel("planned position (pulse)")
    a1.legend()
    a2.step(r["t"], [bool(s & POSITIVE_LIMIT_FLAG) for s in r["sts"]], where="post")
    a2.set_ylabel("GT_GetSts bit 5")
    a2.set_xlabel("controller time (ms)")
    fig.suptitle("example 9-1: soft limit triggered (figure 9-2)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plot", help="write the position / limit-flag figure (PNG) here")
    args = ap.parse_args(argv)
    r = run()
    flag = bool(r["sts"][-1] & POSITIVE_LIMIT_FLAG)
    k = r["stopped"]
    print(f"stopped at {r['pos'][-1]:.3f} pulses after {r['t'][k]} ms; bit 5 = {int(flag)}")
    for line in r["errors"]:
        print("error:", line)
    if args.plot:
        plot(r, args.plot)
    return 0 if not r["errors"] and flag else 1


if __name__ == "__main__":
    sys.exit(main())
