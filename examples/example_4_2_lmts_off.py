"""Manual example 4-2, "switch the limit alarm off", against the emulator.

    python example_4_2_lmts_off.py

``GT_LmtsOff(1, -1)``: axis 1's positive and negative limits no longer raise
the limit alarm.  The machine (``example_4_3_machine.toml``) leaves axis 1
standing on its positive limit switch: after GT_Reset the status word shows
bit 5, and GT_ClrSts cannot clear it while the switch is watched.  After the
example's GT_LmtsOff, GT_ClrSts clears it for good and the axis may move on in
the positive direction (the flag is latched, 9.2: GT_ClrSts is what clears it).
"""

from __future__ import annotations

import sys
from ctypes import byref, c_double, c_long, c_short
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
ENI = HERE / "manual_fig5_2.eni"
MACHINE = HERE / "example_4_3_machine.toml"
LOG: list[str] = []
POS_LIMIT = 1 << 5


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


def plc_prg() -> int:
    """PROGRAM PLC_PRG of example 4-2."""
    rtn = gt.GT_LmtsOff(1, -1)  # limit alarm off
    return rtn


def bring_up(**options: object) -> None:
    """Manual example 5-5: open, initialise, wait until the bus is ready, start."""
    options.setdefault("log", "")
    options.setdefault("machine", str(MACHINE))
    commandhandler("GT_Open", gt.GT_Open(eni=str(ENI), **options))
    commandhandler("GT_InitEcatComm", gt.GT_InitEcatComm())
    ready = c_short()
    for _ in range(10_000):
        if gt.GT_IsEcatReady(byref(ready)) == 0 and ready.value == 1:
            break
        gt.GTE_Wait(1)
    commandhandler("GT_StartEcatComm", gt.GT_StartEcatComm())
    commandhandler("GT_Reset", gt.GT_Reset())
    gt.GTE_Wait(1)  # one cycle: the flags see the machine


def status(axis: int) -> int:
    sts = c_long()
    commandhandler("GT_GetSts", gt.GT_GetSts(axis, byref(sts), 1, None))
    return sts.value


def clear(axis: int) -> int:
    """GT_ClrSts, then one cycle: the status the next scan sees."""
    commandhandler("GT_ClrSts", gt.GT_ClrSts(axis, 1))
    gt.GTE_Wait(1)
    return status(axis)


def move_positive(axis: int, distance: int) -> float:
    """Trap move of ``distance`` pulses in the positive direction; the planned distance."""
    prf = c_double()
    commandhandler("GT_AxisOn", gt.GT_AxisOn(axis))
    commandhandler("GT_PrfTrap", gt.GT_PrfTrap(axis))
    prm = gt.TTrapPrm()
    commandhandler("GT_GetTrapPrm", gt.GT_GetTrapPrm(axis, byref(prm)))
    prm.acc, prm.dec = 1, 1
    commandhandler("GT_SetTrapPrm", gt.GT_SetTrapPrm(axis, byref(prm)))
    commandhandler("GT_GetPrfPos", gt.GT_GetPrfPos(axis, byref(prf), 1, None))
    start = prf.value
    commandhandler("GT_SetPos", gt.GT_SetPos(axis, round(start) + distance))
    commandhandler("GT_SetVel", gt.GT_SetVel(axis, 10))
    commandhandler("GT_Update", gt.GT_Update(1 << (axis - 1)))
    for _ in range(10_000):  # bounded: on a real machine, until bit 10 falls
        gt.GTE_Wait(1)
        if not status(axis) >> 10 & 1:
            break
    commandhandler("GT_GetPrfPos", gt.GT_GetPrfPos(axis, byref(prf), 1, None))
    return prf.value - start


def run(**options: object) -> dict[str, object]:
    LOG.clear()
    gt.GT_Close()
    bring_up(**options)
    try:
        r: dict[str, object] = {"after_reset": status(1), "clr_sts_limits_on": clear(1)}
        r["rtn"] = plc_prg()
        commandhandler("GT_LmtsOff", r["rtn"])
        r["after_lmts_off"] = status(1)  # latched until GT_ClrSts
        r["clr_sts_limits_off"] = clear(1)
        r["moved"] = move_positive(1, 1000)
        r["after_move"] = status(1)
        return {**r, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def main() -> int:
    r = run()
    for key in ("after_reset", "clr_sts_limits_on", "after_lmts_off", "clr_sts_limits_off"):
        print(f"{key:20s} status 0x{r[key]:04X}")
    print(f"then moved {r['moved']:+g} pulses toward the switch, status 0x{r['after_move']:04X}")
    for line in r["errors"]:
        print("error:", line)
    ok = not r["errors"] and not r["clr_sts_limits_off"] & POS_LIMIT and r["moved"] == 1000
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
