"""Manual example 7-8, "Follow double-FIFO switch" (tables 7-11..7-13, figures 7-14, 7-19, 7-20).

    python example_7_8_follow_switch.py [--plot switch.png]

Axis 1 (master) jogs at 50 pulse/ms (acc 1); axis 2 (slave) follows it in
Follow mode, starting at once.  FIFO1 holds the original strategy (table 7-11,
ratio 0 -> 1 -> 1 -> 0 per 60000 master pulses, endless).  When the operator
raises ``xStart`` a second time the program loads the transition (table 7-12,
first segment CONTINUE) into FIFO2 and calls GT_FollowSwitch: at the end of the
running pass the controller clears FIFO1 and runs FIFO2.  Seeing FIFO1 empty
(space 16) the program loads the new strategy (table 7-13, ratio 0.6 -> 1 -> 1 ->
0.6, first segment CONTINUE) into FIFO1 and switches again; it runs for ever.

The listing's third FIFO2 point is ``masterPos+220000``; table 7-12 and figure
7-20 say 20000 (a 60000-pulse transition), which is what this program sends.
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

# VAR CONSTANT
STAGE_FIFO1 = 1
STAGE_TO_FIFO2 = 2
STAGE_TO_FIFO1 = 3
STAGE_END = 4


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


@dataclass
class PlcVars:
    """The VAR block of example 7-8."""

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
    stage: int = STAGE_END


def send(v: PlcVars, points: list[tuple[int, float, int]], fifo: int) -> None:
    """GT_FollowData of (master length, slave length, type) segments as cumulative points."""
    v.masterPos, v.slavePos = 0, 0.0
    for dm, ds, kind in points:
        v.masterPos += dm
        v.slavePos += ds
        v.rtn = gt.GT_FollowData(v.Slave, v.masterPos, v.slavePos, kind, fifo)
        commandhandler("GT_FollowData", v.rtn)


N, C = gt.FOLLOW_SEGMENT_NORMAL, gt.FOLLOW_SEGMENT_CONTINUE
TABLE_7_11 = [(20000, 10000, N), (20000, 20000, N), (20000, 10000, N)]
TABLE_7_12 = [(20000, 10000, C), (20000, 20000, N), (20000, 16000, N)]
TABLE_7_13 = [(20000, 16000, C), (20000, 20000, N), (20000, 16000, N)]


def plc_prg(v: PlcVars) -> None:
    """One scan of example 7-8."""
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
    mask = 1 << (v.Slave - 1)
    if v.xStart:
        if v.stage == STAGE_END:
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
            v.rtn = gt.GT_Update(1 << (v.Master - 1))
            commandhandler("GT_Update", v.rtn)
            v.rtn = gt.GT_PrfFollow(v.Slave, 0)
            commandhandler("GT_PrfFollow", v.rtn)
            v.rtn = gt.GT_FollowClear(v.Slave, 0)
            commandhandler("GT_FollowClear", v.rtn)
            v.rtn = gt.GT_SetFollowMaster(v.Slave, v.Master, gt.FOLLOW_MASTER_PROFILE, 1)
            commandhandler("GT_SetFollowMaster", v.rtn)
            space = c_short()
            v.rtn = gt.GT_FollowSpace(v.Slave, byref(space), 0)
            v.space = space.value
            send(v, TABLE_7_11, 0)  # FIFO1: the original strategy
            v.rtn = gt.GT_SetFollowLoop(v.Slave, 0)  # endless
            commandhandler("GT_SetFollowLoop", v.rtn)
            v.rtn = gt.GT_SetFollowEvent(v.Slave, gt.FOLLOW_EVENT_START, 1, 0)
            commandhandler("GT_SetFollowEvent", v.rtn)
            v.rtn = gt.GT_FollowStart(mask, 0)
            commandhandler("GT_FollowStart", v.rtn)
            v.stage = STAGE_FIFO1
        elif v.stage == STAGE_FIFO1:
            v.rtn = gt.GT_FollowClear(v.Slave, 1)
            commandhandler("GT_FollowClear", v.rtn)
            send(v, TABLE_7_12, 1)  # FIFO2: the transition
            v.rtn = gt.GT_FollowSwitch(mask)  # takes effect when FIFO1's pass ends
            commandhandler("GT_FollowSwitch", v.rtn)
            v.stage = STAGE_TO_FIFO2
        v.xStart = False
    # FIFO1 emptied by the controller -> the switch happened: load the new strategy
    if v.stage == STAGE_TO_FIFO2:
        space = c_short()
        v.rtn = gt.GT_FollowSpace(v.Slave, byref(space), 0)
        v.space = space.value
        if v.space == 16:
            v.stage = STAGE_TO_FIFO1
            send(v, TABLE_7_13, 0)
            v.rtn = gt.GT_FollowSwitch(mask)
            commandhandler("GT_FollowSwitch", v.rtn)
    elif v.stage == STAGE_TO_FIFO1:
        space = c_short()
        v.rtn = gt.GT_FollowSpace(v.Slave, byref(space), 1)
        v.space = space.value
        if v.space == 16:  # FIFO2 emptied: FIFO1 runs the new strategy
            v.stage = STAGE_END
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


def run(scans: int = 6000, switch_at: float = 30000, **options: object) -> dict[str, object]:
    """Init, start; raise ``xStart`` again once the master passes ``switch_at``; 1 ms scans.

    ``stage`` is the program's stage after each scan.
    """
    LOG.clear()
    gt.GT_Close()
    bring_up(**options)
    try:
        v = PlcVars()
        plc_prg(v)  # init scan
        v.xStart = True
        plc_prg(v)  # start scan (STAGE_END -> STAGE_FIFO1)
        clock = c_long()
        gt.GT_GetClock(byref(clock))
        t0 = clock.value
        keys = ("t", "master", "slave", "vmaster", "vslave", "stage")
        r: dict[str, list] = {k: [] for k in keys}
        pressed = None
        for k in range(scans):
            gt.GTE_Wait(1)
            if pressed is None and v.arrPrfPos[0] > switch_at:
                v.xStart = True  # the operator asks for the new strategy
                pressed = k
            plc_prg(v)
            gt.GT_GetClock(byref(clock))
            r["t"].append(clock.value - t0)
            r["master"].append(v.arrPrfPos[0])
            r["slave"].append(v.arrPrfPos[1])
            r["vmaster"].append(v.arrPrfVel[0])
            r["vslave"].append(v.arrPrfVel[1])
            r["stage"].append(v.stage)
        return {**r, "pressed": pressed, "errors": list(LOG)}
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
    ax.set_title("example 7-8: Follow, strategy changed through the two FIFOs (figure 7-20)")
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
        f"stage {r['stage'][-1]} (4 = new strategy running), master at {r['master'][-1]:.0f}, "
        f"slave at {r['slave'][-1]:.0f}"
    )
    for line in r["errors"]:
        print("error:", line)
    if args.plot:
        plot(r, args.plot)
    return 0 if not r["errors"] and r["stage"][-1] == STAGE_END else 1


if __name__ == "__main__":
    sys.exit(main())
