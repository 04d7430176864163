"""Manual example 7-5, "electronic gear" (figures 7-11, 7-12), against the emulator.

    python example_7_5_gear.py [--plot gear.png]

Axis 1 (master) jogs to 100 pulse/ms with acc 1 pulse/ms²; axis 2 (slave)
follows its planned position in Gear mode with master speed : slave speed =
2 : 1 (GT_SetGearRatio(2, 2, 1, 100000)).  The clutch zone is measured in master
travel (7.5.2 note): the ratio grows linearly from 0 to 1/2 while the master
moves 100000 pulses (1050 ms here), so the slave moves (0 + 1/2)/2·100000 =
25000 pulses in the clutch and runs at 50 pulse/ms after it.
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
    """The VAR block of example 7-5."""

    xInitDone: bool = False
    rtn: int = 0
    Master: int = 1
    Slave: int = 2
    xStart: bool = False
    arrPrfVel: list[float] = field(default_factory=lambda: [0.0] * 8)
    arrPrfPos: list[float] = field(default_factory=lambda: [0.0] * 8)  # added: positions


def plc_prg(v: PlcVars) -> None:
    """One scan of example 7-5."""
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
        v.rtn = gt.GT_PrfJog(v.Master)  # master: Jog
        commandhandler("GT_PrfJog", v.rtn)
        jog = gt.TJogPrm()
        v.rtn = gt.GT_GetJogPrm(v.Master, byref(jog))
        commandhandler("GT_GetJogPrm", v.rtn)
        jog.acc = 1
        v.rtn = gt.GT_SetJogPrm(v.Master, byref(jog))
        commandhandler("GT_SetJogPrm", v.rtn)
        v.rtn = gt.GT_SetVel(v.Master, 100)
        commandhandler("GT_SetVel", v.rtn)
        v.rtn = gt.GT_Update(1 << (v.Master - 1))  # start the master
        commandhandler("GT_Update", v.rtn)
        v.rtn = gt.GT_PrfGear(v.Slave, 0)  # slave: Gear, both directions
        commandhandler("GT_PrfGear", v.rtn)
        v.rtn = gt.GT_SetGearMaster(v.Slave, v.Master, gt.GEAR_MASTER_PROFILE, 0)
        commandhandler("GT_SetGearMaster", v.rtn)
        v.rtn = gt.GT_SetGearRatio(v.Slave, 2, 1, 100000)  # 2:1, clutch 100000 master pulses
        commandhandler("GT_SetGearRatio", v.rtn)
        v.rtn = gt.GT_GearStart(1 << (v.Slave - 1))
        commandhandler("GT_GearStart", v.rtn)
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


def run(scans: int = 2000, **options: object) -> dict[str, object]:
    """Init, start, then ``scans`` scans of 1 ms; positions and speeds of both axes per scan."""
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
        r: dict[str, list] = {k: [] for k in ("t", "master", "slave", "vmaster", "vslave")}
        for _ in range(scans):
            gt.GTE_Wait(1)
            plc_prg(v)
            gt.GT_GetClock(byref(clock))
            r["t"].append(clock.value - t0)
            r["master"].append(v.arrPrfPos[0])
            r["slave"].append(v.arrPrfPos[1])
            r["vmaster"].append(v.arrPrfVel[0])
            r["vslave"].append(v.arrPrfVel[1])
        return {**r, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def plot(r: dict[str, object], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(r["t"], r["vmaster"], label="master (axis 1, Jog)")
    ax.plot(r["t"], r["vslave"], label="slave (axis 2, Gear 2:1)")
    ax.axvline(1050, color="0.6", lw=0.8, ls="--", label="end of the clutch zone")
    ax.set_xlabel("time since the start (ms)")
    ax.set_ylabel("planned velocity (pulse/ms)")
    ax.set_title("example 7-5: electronic gear, clutch over 100000 master pulses")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plot", help="write the velocity figure (PNG) here")
    args = ap.parse_args(argv)
    r = run()
    k = next(i for i, m in enumerate(r["master"]) if m >= 100000)
    print(
        f"master {r['vmaster'][-1]:g} pulse/ms, slave {r['vslave'][-1]:g} pulse/ms; "
        f"slave at {r['slave'][k]:.0f} when the master passed {r['master'][k]:.0f}"
    )
    for line in r["errors"]:
        print("error:", line)
    if args.plot:
        plot(r, args.plot)
    return 0 if not r["errors"] and abs(r["vslave"][-1] - 50) < 1e-9 else 1


if __name__ == "__main__":
    sys.exit(main())
