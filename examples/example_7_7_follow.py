"""Manual example 7-7, "Follow single FIFO" (table 7-10, figures 7-17, 7-18), against the emulator.

    python example_7_7_follow.py [--plot follow.png]

Axis 1 (master) jogs at 50 pulse/ms (acc 1); axis 2 (slave) follows its planned
position in Follow mode.  The slave starts when the master passes 50000 pulses
going positive (FOLLOW_EVENT_PASS): the pass point is the zero of the cam.
Table 7-10's segments (points 20000/10000, 40000/30000, 60000/40000, all NORMAL)
make a trapezoid of the speed ratio: 0 -> 1 over 20000 master pulses, 1 for
20000, 1 -> 0 for 20000; GT_SetFollowLoop(0) repeats it for ever.
"""

# ruff: noqa: N815  (the PLC variables keep the manual's names)
from __future__ import annotations

import argparse
import sys
from ctypes import byref, c_double, c_long, c_short
from dataclasses import dataclass, field
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
    """The VAR block of example 7-7."""

    xInitDone: bool = False
    rtn: int = 0
    Master: int = 1
    Slave: int = 2
    xStart: bool = False
    arrPrfVel: list[float] = field(default_factory=lambda: [0.0] * 8)
    arrPrfPos: list[float] = field(default_factory=lambda: [0.0] * 8)  # added: positions
    space: int = 0
    masterPos: int = 0
    slavePos: float = 0.0


def follow_data(v: PlcVars, dmaster: int, dslave: float) -> None:
    space = c_short()
    v.rtn = gt.GT_FollowSpace(v.Slave, byref(space), 0)
    v.space = space.value
    v.masterPos += dmaster
    v.slavePos += dslave
    v.rtn = gt.GT_FollowData(v.Slave, v.masterPos, v.slavePos, gt.FOLLOW_SEGMENT_NORMAL, 0)
    commandhandler("GT_FollowData", v.rtn)


def plc_prg(v: PlcVars) -> None:
    """One scan of example 7-7."""
    if not v.xInitDone:
        v.rtn = gt.GT_LoadConfig(str(CONFIG))  # alarms and limits off
        commandhandler("GT_LoadConfig", v.rtn)
        v.rtn = gt.GT_ClrSts(1, 8)
        commandhandler("GT_ClrSts", v.rtn)
        v.rtn = gt.GT_AxisOn(v.Master)
        commandhandler("GT_AxisOn", v.rtn)
        v.rtn = gt.GT_AxisOn(v.Slave)
        commandhandler("GT_AxisOn", v.rtn)
        v.xInitDone = True
    if v.xStart:
        v.rtn = gt.GT_ZeroPos(v.Master, 1)
        commandhandler("GT_ZeroPos", v.rtn)
        v.rtn = gt.GT_ZeroPos(v.Slave, 1)
        commandhandler("GT_ZeroPos", v.rtn)
        v.rtn = gt.GT_PrfJog(v.Master)
        commandhandler("GT_PrfJog", v.rtn)
        jog = gt.TJogPrm()
        v.rtn = gt.GT_GetJogPrm(v.Master, byref(jog))
        commandhandler("GT_GetJogPrm", v.rtn)
        jog.acc = 1
        v.rtn = gt.GT_SetJogPrm(v.Master, byref(jog))
        commandhandler("GT_SetJogPrm", v.rtn)
        v.rtn = gt.GT_SetVel(v.Master, 50)
        commandhandler("GT_SetVel", v.rtn)
        v.rtn = gt.GT_Update(1 << (v.Master - 1))  # start the master
        commandhandler("GT_Update", v.rtn)
        v.rtn = gt.GT_PrfFollow(v.Slave, 0)  # slave: Follow, both directions
        commandhandler("GT_PrfFollow", v.rtn)
        v.rtn = gt.GT_FollowClear(v.Slave, 0)
        commandhandler("GT_FollowClear", v.rtn)
        # the master's planned position (masterItem only matters for FOLLOW_MASTER_AXIS)
        v.rtn = gt.GT_SetFollowMaster(v.Slave, v.Master, gt.FOLLOW_MASTER_PROFILE, 1)
        commandhandler("GT_SetFollowMaster", v.rtn)
        v.masterPos, v.slavePos = 0, 0.0
        follow_data(v, 20000, 10000)  # accelerate
        follow_data(v, 20000, 20000)  # ratio 1
        follow_data(v, 20000, 10000)  # decelerate
        v.rtn = gt.GT_SetFollowLoop(v.Slave, 0)  # endless
        commandhandler("GT_SetFollowLoop", v.rtn)
        v.rtn = gt.GT_SetFollowEvent(v.Slave, gt.FOLLOW_EVENT_PASS, 1, 50000)
        commandhandler("GT_SetFollowEvent", v.rtn)
        v.rtn = gt.GT_FollowStart(1 << (v.Slave - 1), 0)
        commandhandler("GT_FollowStart", v.rtn)
        v.xStart = False
    vel = (c_double * 8)()
    v.rtn = gt.GT_GetPrfVel(1, vel, 8, 0)  # as the manual: 8 profiles, whatever the bus holds
    commandhandler("GT_GetPrfVel", v.rtn)  # added: the manual leaves it unchecked
    v.arrPrfVel[:] = list(vel)
    pos = (c_double * 8)()
    v.rtn = gt.GT_GetPrfPos(1, pos, 8, 0)
    commandhandler("GT_GetPrfPos", v.rtn)
    v.arrPrfPos[:] = list(pos)


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


def run(scans: int = 6000, **options: object) -> dict[str, object]:
    """Init, start, ``scans`` scans of 1 ms: positions, speeds, loops done, slave status."""
    LOG.clear()
    gt.GT_Close()
    bring_up(**options)
    try:
        v = PlcVars()
        plc_prg(v)  # init scan
        v.xStart = True
        plc_prg(v)  # start scan
        clock = c_long()
        gt.GT_GetClock(byref(clock))
        t0 = clock.value
        keys = ("t", "master", "slave", "vmaster", "vslave", "loop", "sts")
        r: dict[str, list] = {k: [] for k in keys}
        loop, sts = c_long(), c_long()
        for _ in range(scans):
            gt.GTE_Wait(1)
            plc_prg(v)
            gt.GT_GetClock(byref(clock))
            gt.GT_GetFollowLoop(v.Slave, byref(loop))
            gt.GT_GetSts(v.Slave, byref(sts))
            r["t"].append(clock.value - t0)
            r["master"].append(v.arrPrfPos[0])
            r["slave"].append(v.arrPrfPos[1])
            r["vmaster"].append(v.arrPrfVel[0])
            r["vslave"].append(v.arrPrfVel[1])
            r["loop"].append(loop.value)
            r["sts"].append(sts.value)
        return {**r, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def plot(r: dict[str, object], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(r["t"], r["vmaster"], label="master (axis 1, Jog 50)")
    ax.plot(r["t"], r["vslave"], label="slave (axis 2, Follow)")
    ax.set_xlabel("time since the start (ms)")
    ax.set_ylabel("planned velocity (pulse/ms)")
    ax.set_title("example 7-7: Follow, one FIFO, start after the master passes 50000")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plot", help="write the velocity figure (PNG) here")
    args = ap.parse_args(argv)
    r = run()
    print(
        f"master at {r['master'][-1]:.0f}, slave at {r['slave'][-1]:.0f}, "
        f"{r['loop'][-1]} passes done, slave speed now {r['vslave'][-1]:.2f} pulse/ms"
    )
    for line in r["errors"]:
        print("error:", line)
    if args.plot:
        plot(r, args.plot)
    return 0 if not r["errors"] and r["loop"][-1] >= 3 else 1


if __name__ == "__main__":
    sys.exit(main())
