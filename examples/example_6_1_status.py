"""Manual example 6-1, "axis 1's status, mode, position, velocity and acceleration".

    python example_6_1_status.py

:func:`plc_prg` is the manual's program: it decodes the status word of
GT_GetSts bit by bit (table 6-2) and reads the planned position, velocity,
acceleration and the motion mode.  The script runs it once per millisecond
(one PLC scan, ``GTE_Wait(1)``) while axis 1 makes a short Trap move, and keeps
what each scan saw.
"""

# ruff: noqa: N815  (the PLC variables keep the manual's names)
from __future__ import annotations

import sys
from ctypes import byref, c_double, c_long, c_short
from dataclasses import dataclass, field
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
ENI = HERE / "manual_fig5_2.eni"
MODES = {0: "Trap", 1: "Jog", 2: "PT", 3: "Gear", 4: "Follow", 5: "Interpolation", 6: "PVT"}
LOG: list[str] = []


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


@dataclass
class PlcVars:
    """The VAR block of example 6-1."""

    Axis: int = 1
    bFlagAlarm: bool = False
    bFlagMError: bool = False
    bFlagPosLimit: bool = False
    bFlagNegLimit: bool = False
    bFlagSmoothStop: bool = False
    bFlagAbruptStop: bool = False
    bFlagServoOn: bool = False
    bFlagMotion: bool = False
    lrPrfPos: float = 0.0
    lrPrfVel: float = 0.0
    lrPrfAcc: float = 0.0
    diPrfMode: int = 0
    sPrfMode: str = ""
    dwAxisStatus: int = 0
    rtn: int = 0
    scans: list[dict[str, object]] = field(default_factory=list)


def plc_prg(v: PlcVars) -> None:
    """One scan of example 6-1."""
    sts = c_long()
    v.rtn = gt.GT_GetSts(v.Axis, byref(sts), 1, None)  # read the axis status
    commandhandler("GT_GetSts", v.rtn)
    v.dwAxisStatus = sts.value & 0xFFFFFFFF
    bit = v.dwAxisStatus
    v.bFlagAlarm = bool(bit >> 1 & 1)  # drive alarm
    v.bFlagMError = bool(bit >> 4 & 1)  # following error over the limit
    v.bFlagPosLimit = bool(bit >> 5 & 1)  # positive limit
    v.bFlagNegLimit = bool(bit >> 6 & 1)  # negative limit
    v.bFlagSmoothStop = bool(bit >> 7 & 1)  # smooth stop
    v.bFlagAbruptStop = bool(bit >> 8 & 1)  # abrupt stop
    v.bFlagServoOn = bool(bit >> 9 & 1)  # servo enabled
    v.bFlagMotion = bool(bit >> 10 & 1)  # the profile is moving
    pos, vel, acc = c_double(), c_double(), c_double()
    v.rtn = gt.GT_GetPrfPos(v.Axis, byref(pos), 1, None)
    commandhandler("GT_GetPrfPos", v.rtn)
    v.rtn = gt.GT_GetPrfVel(v.Axis, byref(vel), 1, None)
    commandhandler("GT_GetPrfVel", v.rtn)
    v.rtn = gt.GT_GetPrfAcc(v.Axis, byref(acc), 1, None)
    commandhandler("GT_GetPrfAcc", v.rtn)
    v.lrPrfPos, v.lrPrfVel, v.lrPrfAcc = pos.value, vel.value, acc.value
    mode = c_long()
    v.rtn = gt.GT_GetPrfMode(v.Axis, byref(mode), 1, None)  # read the motion mode
    commandhandler("GT_GetPrfMode", v.rtn)
    v.diPrfMode = mode.value
    v.sPrfMode = MODES.get(v.diPrfMode, "?")


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


def start_move(axis: int) -> None:
    """The motion the status program watches: a 2000-pulse Trap move."""
    commandhandler("GT_AxisOn", gt.GT_AxisOn(axis))
    commandhandler("GT_PrfTrap", gt.GT_PrfTrap(axis))
    prm = gt.TTrapPrm()
    commandhandler("GT_GetTrapPrm", gt.GT_GetTrapPrm(axis, byref(prm)))
    prm.acc, prm.dec = 0.5, 0.5
    commandhandler("GT_SetTrapPrm", gt.GT_SetTrapPrm(axis, byref(prm)))
    commandhandler("GT_SetPos", gt.GT_SetPos(axis, 2000))
    commandhandler("GT_SetVel", gt.GT_SetVel(axis, 20))
    commandhandler("GT_Update", gt.GT_Update(1 << (axis - 1)))


def run(scans: int = 200, **options: object) -> dict[str, object]:
    LOG.clear()
    gt.GT_Close()
    bring_up(**options)
    try:
        v = PlcVars()
        plc_prg(v)
        before = dict(servo=v.bFlagServoOn, motion=v.bFlagMotion, mode=v.sPrfMode)
        start_move(v.Axis)
        for _ in range(scans):
            gt.GTE_Wait(1)  # one PLC scan
            plc_prg(v)
            v.scans.append(
                {
                    "status": v.dwAxisStatus,
                    "motion": v.bFlagMotion,
                    "servo": v.bFlagServoOn,
                    "pos": v.lrPrfPos,
                    "vel": v.lrPrfVel,
                    "acc": v.lrPrfAcc,
                    "mode": v.sPrfMode,
                }
            )
        return {"before": before, "scans": v.scans, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def main() -> int:
    r = run()
    scans = r["scans"]
    moving = [s for s in scans if s["motion"]]
    print(f"before the move: {r['before']}")
    print(
        f"{len(moving)} scans with bFlagMotion; peak velocity "
        f"{max(s['vel'] for s in scans):g} pulse/ms; last: {scans[-1]}"
    )
    for line in r["errors"]:
        print("error:", line)
    return 0 if not r["errors"] and scans[-1]["pos"] == 2000 else 1


if __name__ == "__main__":
    sys.exit(main())
