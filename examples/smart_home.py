"""A user's C++ limit homing (``Motion::LimitHome``) in Python, on a virtual GTS-400 card.

    python smart_home.py [axis]

The original is a user's C++ class for a 4-axis Googol GTS card:
``init`` opens the card, resets it, loads ``GTS800.cfg``, clears and zeroes the axes and
switches them on; ``moveHomeInner`` clears and zeroes the axis, escapes a limit it stands on,
reads the smart-home parameters, sets ``HOME_MODE_LIMIT`` (moveDir -1, velHigh 50, velLow
20, acc/dec 5, homeOffset 10000, escapeStep 1000), clears the capture, puts the axis in Trap
mode, calls ``GT_GoHome`` and polls ``GT_GetHomeStatus`` - clearing the limit flag the
search raises - until ``run`` drops, then zeroes the position.  Here is the same flow written
as ctypes code for the vendor DLL would be (``byref``, the structures of ``gt``), against
``GT_Open(card="gts:4")`` (or ``GTECAT_CARD=gts:4``): no ``GT_InitEcatComm``, a card.

The card's mechanics are ``smart_home_machine.toml``: axis 3 (the class's ``Axis_X``) has its
negative limit at -50000 and stands at 0; ``GTS800.cfg`` wires each axis's alarm and limits
to its own terminals.  The search finds the limit (sampled once per 1 ms cycle, so within
half a cycle's travel at velLow: +-10 counts), stops at capture + 10000 and the script zeroes
it there: the axis stands at machine position -40000 with planned and encoder positions 0.
``GTE_GetMachinePos`` (emulator only) shows where the axis really is.
"""

from __future__ import annotations

import sys
from ctypes import byref, c_double, c_long
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
MACHINE = HERE / "smart_home_machine.toml"
CONFIG = HERE / "GTS800.cfg"
ESCAPE_DISTANCE = 1000  # the class's escape_distance


def check(rc: int, what: str) -> None:
    if rc != 0:
        raise RuntimeError(f"{what} returned {rc}: {gt.GTE_GetLastError()}")


def status(axis: int) -> int:
    sts = c_long()
    check(gt.GT_GetSts(axis, byref(sts)), "GT_GetSts")
    return sts.value


def init(clock: str) -> None:
    """Motion::init: open, reset, configuration, clear, zero, servo on (axes 3, 4, 1, 2)."""
    check(gt.GT_Open(card="gts:4", machine=str(MACHINE), clock=clock, log=""), "GT_Open")
    check(gt.GT_Reset(), "GT_Reset")
    check(gt.GT_LoadConfig(str(CONFIG)), "GT_LoadConfig")
    check(gt.GT_ClrSts(1, 4), "GT_ClrSts")
    check(gt.GT_ZeroPos(1, 4), "GT_ZeroPos")
    for axis in (3, 4, 1, 2):
        check(gt.GT_AxisOn(axis), f"GT_AxisOn({axis})")


def limit_home(axis: int) -> gt.THomeStatus:
    """Motion::moveHomeInner: the class's limit homing, call for call."""
    check(gt.GT_ClrSts(axis), "GT_ClrSts")
    check(gt.GT_ZeroPos(axis), "GT_ZeroPos")
    sts = status(axis)
    if sts & 0x60 and sts & (1 << 10):  # on a limit and moving: the class's moveTo stops it
        check(gt.GT_Stop(1 << (axis - 1), 1 << (axis - 1)), "GT_Stop")
    if sts & 0x60:
        check(gt.GT_ClrSts(axis), "GT_ClrSts")
    prm = gt.THomePrm()
    check(gt.GT_GetHomePrm(axis, byref(prm)), "GT_GetHomePrm")
    prm.mode = gt.HOME_MODE_LIMIT
    prm.moveDir = -1
    prm.triggerIndex = -1
    prm.velHigh = 50
    prm.velLow = 20
    prm.acc = 5
    prm.dec = 5
    prm.smoothTime = 0
    prm.homeOffset = 10000
    prm.searchHomeDistance = 0  # search without limit
    prm.escapeStep = ESCAPE_DISTANCE
    check(gt.GT_ClearCaptureStatus(axis), "GT_ClearCaptureStatus")
    check(gt.GT_PrfTrap(axis), "GT_PrfTrap")
    check(gt.GT_GoHome(axis, byref(prm)), "GT_GoHome")
    home = gt.THomeStatus()
    while True:
        check(gt.GT_GetHomeStatus(axis, byref(home)), "GT_GetHomeStatus")
        check(gt.GT_ClrSts(axis), "GT_ClrSts")  # the limit flag the search raised
        if not home.run:
            break
        if gt.GTE_Controller().options.clock == "lockstep":
            gt.GTE_Wait(1)  # lockstep: nothing moves until time is let pass
    check(gt.GT_ClrSts(axis), "GT_ClrSts")
    check(gt.GT_ZeroPos(axis, 1), "GT_ZeroPos")
    return home


def run(axis: int = 3, clock: str = "auto") -> dict:
    """The whole flow; what it observed (positions in pulses / machine counts)."""
    init(clock)
    try:
        home = limit_home(axis)
        prf, enc, machine = c_double(), c_double(), c_double()
        check(gt.GT_GetPrfPos(axis, byref(prf)), "GT_GetPrfPos")
        check(gt.GT_GetEncPos(axis, byref(enc)), "GT_GetEncPos")
        check(gt.GTE_GetMachinePos(axis, byref(machine)), "GTE_GetMachinePos")
        return {
            "stage": home.stage,
            "error": home.error,
            "capturePos": home.capturePos,
            "targetPos": home.targetPos,
            "prf": prf.value,
            "enc": enc.value,
            "machine": machine.value,
            "sts": status(axis),
        }
    finally:
        gt.GT_Close()


def main(argv: list[str]) -> int:
    axis = int(argv[1]) if len(argv) > 1 else 3
    r = run(axis)
    print(f"home stage {r['stage']} error {r['error']}")
    print(f"capturePos {r['capturePos']} targetPos {r['targetPos']}")
    print(f"after GT_ZeroPos: prf {r['prf']:.0f} enc {r['enc']:.0f}, machine {r['machine']:.0f}")
    return 0 if r["error"] == gt.HOME_ERROR_NONE and r["stage"] == gt.HOME_STAGE_END else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
