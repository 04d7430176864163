"""Manual example 4-1, "set the encoder counting direction", against the emulator.

    python example_4_1_enc_sns.py

``GT_EncSns(16#01)`` reverses encoder 1 and leaves the others as they are
(table 4-3: bit n-1 = encoder n).  To show it, axes 1 and 2 of the figure 5-2
bus then both move +1000 pulses (Trap): encoder 1 counts -1000, encoder 2 +1000
- "编码器位置和规划位置方向不一致" (4.5.3 step 6) on axis 1 only.
"""

from __future__ import annotations

import sys
from ctypes import byref, c_double, c_long, c_short
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
ENI = HERE / "manual_fig5_2.eni"
LOG: list[str] = []
MOVE = 1000


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


def plc_prg() -> int:
    """PROGRAM PLC_PRG of example 4-1."""
    rtn = gt.GT_EncSns(0x01)
    return rtn


def bring_up(**options: object) -> None:
    """Manual example 5-5: open, initialise, wait until the bus is ready, start."""
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
    gt.GTE_Wait(1)


def read(call, axis: int) -> float:
    value = c_double()
    commandhandler(call.__name__, call(axis, byref(value), 1, None))
    return value.value


def move(axes: list[int], distance: int) -> None:
    """Trap move of every axis by ``distance`` pulses; wait until none moves (bit 10)."""
    mask = 0
    for axis in axes:
        commandhandler("GT_AxisOn", gt.GT_AxisOn(axis))
        commandhandler("GT_PrfTrap", gt.GT_PrfTrap(axis))
        prm = gt.TTrapPrm()
        commandhandler("GT_GetTrapPrm", gt.GT_GetTrapPrm(axis, byref(prm)))
        prm.acc, prm.dec = 1, 1
        commandhandler("GT_SetTrapPrm", gt.GT_SetTrapPrm(axis, byref(prm)))
        start = round(read(gt.GT_GetPrfPos, axis))
        commandhandler("GT_SetPos", gt.GT_SetPos(axis, start + distance))
        commandhandler("GT_SetVel", gt.GT_SetVel(axis, 10))
        mask |= 1 << (axis - 1)
    commandhandler("GT_Update", gt.GT_Update(mask))
    sts = c_long()
    for _ in range(10_000):  # bounded: a real axis would be watched until it stops
        gt.GTE_Wait(1)
        moving = False
        for axis in axes:
            commandhandler("GT_GetSts", gt.GT_GetSts(axis, byref(sts), 1, None))
            moving |= bool(sts.value >> 10 & 1)
        if not moving:
            break


def run(**options: object) -> dict[str, object]:
    LOG.clear()
    gt.GT_Close()
    bring_up(**options)
    try:
        rtn = plc_prg()
        commandhandler("GT_EncSns", rtn)
        axes = [1, 2]
        prf0 = {a: read(gt.GT_GetPrfPos, a) for a in axes}
        enc0 = {a: read(gt.GT_GetEncPos, a) for a in axes}
        move(axes, MOVE)
        gt.GTE_Wait(5)  # the drives settle on the target
        prf = {a: read(gt.GT_GetPrfPos, a) - prf0[a] for a in axes}
        enc = {a: read(gt.GT_GetEncPos, a) - enc0[a] for a in axes}
        return {"rtn": rtn, "prf_moved": prf, "enc_moved": enc, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def main() -> int:
    r = run()
    for axis in (1, 2):
        print(f"axis {axis}: planned {r['prf_moved'][axis]:+g}, encoder {r['enc_moved'][axis]:+g}")
    for line in r["errors"]:
        print("error:", line)
    ok = not r["errors"] and r["enc_moved"] == {1: -MOVE, 2: MOVE}
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
