"""Manual example 7-2, "Jog motion" (figure 7-4): the target speed changed on the fly.

    python example_7_2_jog.py [--plot jog.png]

Axis 1 jogs at 100 pulse/ms (acc = dec = 0.0625 pulse/ms²: 1600 ms to speed);
once the planned position passes 100000 pulses the program sets 50 pulse/ms and
calls GT_Update again: the speed falls to 50 in 800 ms and stays there.
:func:`plc_prg` is the manual's program, one scan per millisecond; ``xUpdate``
is raised by the script (the HMI of the manual) when the position passes 100000.
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
    """The VAR block of example 7-2."""

    xInitDone: bool = False
    rtn: int = 0
    Axis: int = 1
    xStart: bool = False
    xUpdate: bool = False
    lrPrfPos: float = 0.0
    lrPrfVel: float = 0.0
    dwAxisStatus: int = 0


def plc_prg(v: PlcVars) -> None:
    """One scan of example 7-2."""
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
        v.rtn = gt.GT_PrfJog(v.Axis)  # Jog mode
        commandhandler("GT_PrfJog", v.rtn)
        jog = gt.TJogPrm()
        v.rtn = gt.GT_GetJogPrm(v.Axis, byref(jog))  # read every parameter first
        commandhandler("GT_GetJogPrm", v.rtn)
        jog.acc = 0.0625
        jog.dec = 0.0625
        v.rtn = gt.GT_SetJogPrm(v.Axis, byref(jog))
        commandhandler("GT_SetJogPrm", v.rtn)
        v.rtn = gt.GT_SetVel(v.Axis, 100)  # target speed
        commandhandler("GT_SetVel", v.rtn)
        v.rtn = gt.GT_Update(1 << (v.Axis - 1))  # start
        commandhandler("GT_Update", v.rtn)
        v.xStart = False
    if v.xUpdate:
        v.rtn = gt.GT_SetVel(v.Axis, 50)  # new target speed
        commandhandler("GT_SetVel", v.rtn)
        v.rtn = gt.GT_Update(1 << (v.Axis - 1))
        commandhandler("GT_Update", v.rtn)
        v.xUpdate = False
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


def run(scans: int = 3500, **options: object) -> dict[str, object]:
    """Init, start, raise xUpdate past 100000 pulses; the trace of every scan."""
    LOG.clear()
    gt.GT_Close()
    bring_up(**options)
    try:
        v = PlcVars()
        plc_prg(v)
        v.xStart = True
        t, pos, vel = [], [], []
        update_at = None
        clock, t0 = c_long(), None
        for k in range(scans):
            if update_at is None and v.lrPrfPos > 100000:
                v.xUpdate = True
                update_at = k
            plc_prg(v)
            gt.GT_GetClock(byref(clock))
            t0 = clock.value if t0 is None else t0
            t.append(clock.value - t0)
            pos.append(v.lrPrfPos)
            vel.append(v.lrPrfVel)
            gt.GTE_Wait(1)
        return {"t": t, "pos": pos, "vel": vel, "update_at": update_at, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def plot(r: dict[str, object], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(r["t"], r["vel"])
    if r["update_at"] is not None:
        ax.axvline(
            r["t"][r["update_at"]], color="tab:red", lw=0.8, label="GT_SetVel(50) + GT_Update"
        )
        ax.legend()
    ax.set_xlabel("controller time (ms)")
    ax.set_ylabel("planned velocity (pulse/ms)")
    ax.set_title("example 7-2: Jog, target speed changed on the fly (figure 7-4)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plot", help="write the velocity figure (PNG) here")
    args = ap.parse_args(argv)
    r = run()
    print(
        f"speed {max(r['vel']):g} pulse/ms, changed at {r['pos'][r['update_at']]:.0f} pulses, "
        f"now {r['vel'][-1]:g} pulse/ms"
    )
    for line in r["errors"]:
        print("error:", line)
    if args.plot:
        plot(r, args.plot)
    return 0 if not r["errors"] and abs(r["vel"][-1] - 50) < 1e-9 else 1


if __name__ == "__main__":
    sys.exit(main())
