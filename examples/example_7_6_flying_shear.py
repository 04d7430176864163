"""Manual example 7-6, "Follow mode in a flying shear" (figures 7-15, 7-16, tables 7-8, 7-9).

    python example_7_6_flying_shear.py [--plot shear.png]

The belt (axis 1, master) runs in Jog mode; the knife rotor (axis 2, slave)
follows its planned position in Follow mode.  One cut every 10000 pulses of
belt; one rotor turn is 8000 pulses.  The manual gives the data, not a
program; this one is written in the style of its other examples:

* region 1 (table 7-8, FIFO1): the knife stands 2500 pulses before the cut and
  catches up while the belt moves 5000 - one NORMAL segment, ratio 0 -> 1;
* region 2 (table 7-9, FIFO2, endless): five segments per cut, master points
  1000/4000/6000/9000/10000, slave points 1000/3400/4600/7000/8000.  The first and
  last are the speed-synchronous zone around the cut, EVEN segments with ratio
  exactly 1 (slave speed = belt speed); the middle three slow the knife to
  ratio 0.6 and bring it back (NORMAL segments: 1 -> 0.6, 0.6, 0.6 -> 1).

GT_SetFollowLoop(0) makes each FIFO endless; GT_FollowSwitch right after
GT_FollowStart lets region 1 run once: at its end the controller clears FIFO1
and runs FIFO2 for ever (7.6.2 (6)).
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

BELT_SPEED = 50.0  # pulse/ms
#: table 7-8: (master point, slave point, type) of region 1
REGION_1 = [(5000, 2500, gt.FOLLOW_SEGMENT_NORMAL)]
#: table 7-9: region 2, points from the start of the region
REGION_2 = [
    (1000, 1000, gt.FOLLOW_SEGMENT_EVEN),  # speed-synchronous: leaving the cut
    (4000, 3400, gt.FOLLOW_SEGMENT_NORMAL),  # slowing down, ratio 1 -> 0.6
    (6000, 4600, gt.FOLLOW_SEGMENT_NORMAL),  # ratio 0.6
    (9000, 7000, gt.FOLLOW_SEGMENT_NORMAL),  # speeding up, ratio 0.6 -> 1
    (10000, 8000, gt.FOLLOW_SEGMENT_EVEN),  # speed-synchronous: reaching the next cut
]


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


@dataclass
class PlcVars:
    """The variables of the flying-shear program."""

    xInitDone: bool = False
    rtn: int = 0
    Master: int = 1
    Slave: int = 2
    xStart: bool = False
    space: int = 0
    arrPrfVel: list[float] = field(default_factory=lambda: [0.0] * 8)
    arrPrfPos: list[float] = field(default_factory=lambda: [0.0] * 8)
    lLoop: int = 0


def plc_prg(v: PlcVars) -> None:
    """One scan of the flying shear."""
    if not v.xInitDone:
        v.rtn = gt.GT_LoadConfig(str(CONFIG))  # alarms and limits off
        commandhandler("GT_LoadConfig", v.rtn)
        v.rtn = gt.GT_ClrSts(1, 8)
        commandhandler("GT_ClrSts", v.rtn)
        for axis in (v.Master, v.Slave):
            v.rtn = gt.GT_AxisOn(axis)
            commandhandler("GT_AxisOn", v.rtn)
        v.xInitDone = True
    if v.xStart:
        for axis in (v.Master, v.Slave):
            v.rtn = gt.GT_ZeroPos(axis, 1)
            commandhandler("GT_ZeroPos", v.rtn)
        # the belt: Jog
        v.rtn = gt.GT_PrfJog(v.Master)
        commandhandler("GT_PrfJog", v.rtn)
        jog = gt.TJogPrm()
        v.rtn = gt.GT_GetJogPrm(v.Master, byref(jog))
        commandhandler("GT_GetJogPrm", v.rtn)
        jog.acc = 1
        v.rtn = gt.GT_SetJogPrm(v.Master, byref(jog))
        commandhandler("GT_SetJogPrm", v.rtn)
        v.rtn = gt.GT_SetVel(v.Master, BELT_SPEED)
        commandhandler("GT_SetVel", v.rtn)
        v.rtn = gt.GT_Update(1 << (v.Master - 1))
        commandhandler("GT_Update", v.rtn)
        # the knife: Follow the belt's planned position
        v.rtn = gt.GT_PrfFollow(v.Slave, 0)
        commandhandler("GT_PrfFollow", v.rtn)
        for fifo in (0, 1):
            v.rtn = gt.GT_FollowClear(v.Slave, fifo)
            commandhandler("GT_FollowClear", v.rtn)
        v.rtn = gt.GT_SetFollowMaster(v.Slave, v.Master, gt.FOLLOW_MASTER_PROFILE, 0)
        commandhandler("GT_SetFollowMaster", v.rtn)
        for fifo, region in ((0, REGION_1), (1, REGION_2)):
            for master_pos, slave_pos, kind in region:
                space = c_short()
                v.rtn = gt.GT_FollowSpace(v.Slave, byref(space), fifo)
                v.space = space.value
                if v.space > 0:
                    v.rtn = gt.GT_FollowData(v.Slave, master_pos, slave_pos, kind, fifo)
                    commandhandler("GT_FollowData", v.rtn)
        v.rtn = gt.GT_SetFollowLoop(v.Slave, 0)  # endless
        commandhandler("GT_SetFollowLoop", v.rtn)
        v.rtn = gt.GT_SetFollowEvent(v.Slave, gt.FOLLOW_EVENT_START, 1, 0)  # start at once
        commandhandler("GT_SetFollowEvent", v.rtn)
        v.rtn = gt.GT_FollowStart(1 << (v.Slave - 1), 0)  # region 1 from FIFO1
        commandhandler("GT_FollowStart", v.rtn)
        v.rtn = gt.GT_FollowSwitch(1 << (v.Slave - 1))  # then region 2, for ever
        commandhandler("GT_FollowSwitch", v.rtn)
        v.xStart = False
    vel = (c_double * 8)()
    v.rtn = gt.GT_GetPrfVel(1, vel, 8, 0)  # as the manual: 8 profiles, whatever the bus holds
    commandhandler("GT_GetPrfVel", v.rtn)  # added: the manual leaves it unchecked
    v.arrPrfVel[:] = list(vel)
    pos = (c_double * 8)()
    v.rtn = gt.GT_GetPrfPos(1, pos, 8, 0)
    commandhandler("GT_GetPrfPos", v.rtn)
    v.arrPrfPos[:] = list(pos)
    loop = c_long()
    v.rtn = gt.GT_GetFollowLoop(v.Slave, byref(loop))
    v.lLoop = loop.value


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


def run(scans: int = 2500, **options: object) -> dict[str, object]:
    """Init, start, ``scans`` scans of 1 ms: both axes' positions and speeds, FIFO1's space."""
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
        keys = ("t", "master", "slave", "vmaster", "vslave", "space0", "loop")
        r: dict[str, list] = {k: [] for k in keys}
        space = c_short()
        for _ in range(scans):
            gt.GTE_Wait(1)
            plc_prg(v)
            gt.GT_GetClock(byref(clock))
            gt.GT_FollowSpace(v.Slave, byref(space), 0)
            r["t"].append(clock.value - t0)
            r["master"].append(v.arrPrfPos[0])
            r["slave"].append(v.arrPrfPos[1])
            r["vmaster"].append(v.arrPrfVel[0])
            r["vslave"].append(v.arrPrfVel[1])
            r["space0"].append(space.value)
            r["loop"].append(v.lLoop)
        return {**r, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def cuts(r: dict[str, list]) -> list[tuple[float, float]]:
    """(belt, knife) positions at each cut: belt at 5000 + k·10000."""
    out = []
    k = 0
    for m, s in zip(r["master"], r["slave"], strict=True):
        if m >= 5000 + 10000 * k:
            out.append((m, s))
            k += 1
    return out


def plot(r: dict[str, object], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(2, 1, sharex=True, figsize=(8, 5))
    a1.plot(r["master"], r["vmaster"], label="belt (master)")
    a1.plot(r["master"], r["vslave"], label="knife (slave)")
    a1.set_ylabel("planned velocity (pulse/ms)")
    a1.legend()
    a2.plot(r["master"], r["slave"])
    a2.set_ylabel("knife position (pulse)")
    a2.set_xlabel("belt position (pulse)")
    fig.suptitle("example 7-6: flying shear, 8000 knife pulses per 10000 belt pulses")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plot", help="write the velocity/position figure (PNG) here")
    args = ap.parse_args(argv)
    r = run()
    c = cuts(r)
    print(f"{len(c)} cuts; knife at each cut: " + ", ".join(f"{s:.0f}" for _, s in c))
    for line in r["errors"]:
        print("error:", line)
    if args.plot:
        plot(r, args.plot)
    return 0 if not r["errors"] and len(c) > 1 else 1


if __name__ == "__main__":
    sys.exit(main())
