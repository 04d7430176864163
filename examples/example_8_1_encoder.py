"""Manual example 8-1, "access the encoders", against the emulator.

    python example_8_1_encoder.py

The manual's program reads eight encoder positions and eight encoder speeds in
one call each (``GT_GetEncPos(1, ADR(enc), 8, 0)``, ``enc: ARRAY [0..7] OF
LREAL``).  Eight encoders need eight axes, so this runs on ``twelve_axes.eni``;
the mechanics of axis n stand at n·1000 counts (the encoders read them), and
axis 1 moves at 10 pulse/ms while the program reads, so speed 1 is 10.
"""

from __future__ import annotations

import sys
from ctypes import byref, c_double, c_short
from pathlib import Path

from gtecat import gt
from gtecat.drives.machine import AxisMachine, MachineDescription

HERE = Path(__file__).resolve().parent
ENI = HERE / "twelve_axes.eni"
MACHINE = MachineDescription(
    axes={n: AxisMachine(position=1000.0 * n) for n in range(1, 9)}, source="example 8-1"
)
LOG: list[str] = []


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


def plc_prg() -> tuple[list[float], list[float]]:
    """PROGRAM PLC_PRG of example 8-1: (enc, vel)."""
    enc = (c_double * 8)()  # ARRAY [0..7] OF LREAL
    vel = (c_double * 8)()
    rtn = gt.GT_GetEncPos(1, byref(enc), 8, 0)  # the positions of 8 encoders
    commandhandler("GT_GetEncPos", rtn)
    rtn = gt.GT_GetEncVel(1, byref(vel), 8, 0)  # the speeds of 8 encoders
    commandhandler("GT_GetEncVel", rtn)
    return list(enc), list(vel)


def bring_up(**options: object) -> None:
    """Manual example 5-5: open, initialise, wait until the bus is ready, start."""
    options.setdefault("log", "")
    options.setdefault("machine", MACHINE)
    commandhandler("GT_Open", gt.GT_Open(eni=str(ENI), **options))
    commandhandler("GT_InitEcatComm", gt.GT_InitEcatComm())
    ready = c_short()
    for _ in range(10_000):
        if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
            break
        gt.GTE_Wait(1)
    commandhandler("GT_StartEcatComm", gt.GT_StartEcatComm())
    commandhandler("GT_Reset", gt.GT_Reset())
    gt.GTE_Wait(1)


def start_axis_1() -> None:
    """Axis 1 moves 5000 pulses at 10 pulse/ms (acc 1 pulse/ms²)."""
    commandhandler("GT_AxisOn", gt.GT_AxisOn(1))
    commandhandler("GT_PrfTrap", gt.GT_PrfTrap(1))
    prm = gt.TTrapPrm()
    commandhandler("GT_GetTrapPrm", gt.GT_GetTrapPrm(1, byref(prm)))
    prm.acc, prm.dec = 1, 1
    commandhandler("GT_SetTrapPrm", gt.GT_SetTrapPrm(1, byref(prm)))
    commandhandler("GT_SetPos", gt.GT_SetPos(1, 1000 + 5000))
    commandhandler("GT_SetVel", gt.GT_SetVel(1, 10))
    commandhandler("GT_Update", gt.GT_Update(1))


def run(**options: object) -> dict[str, object]:
    LOG.clear()
    gt.GT_Close()
    bring_up(**options)
    try:
        standing = plc_prg()
        start_axis_1()
        gt.GTE_Wait(200)  # well into the constant-speed part
        moving = plc_prg()
        return {"standing": standing, "moving": moving, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def main() -> int:
    r = run()
    for when in ("standing", "moving"):
        enc, vel = r[when]
        print(f"{when:8s} enc = {[round(x, 3) for x in enc]}")
        print(f"{'':8s} vel = {[round(x, 3) for x in vel]}")
    for line in r["errors"]:
        print("error:", line)
    enc, vel = r["standing"]
    ok = not r["errors"] and enc == [1000.0 * n for n in range(1, 9)] and r["moving"][1][0] == 10
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
