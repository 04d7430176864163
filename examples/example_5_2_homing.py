"""Manual example 5-2, "homing with method 3", as a Python script against the emulator.

    python example_5_2_homing.py

The Structured Text program of the manual runs once per PLC scan; here
:func:`plc_prg` is that program (its VAR block is :class:`PlcVars`) and the main
loop calls it once per millisecond of controller time (``GTE_Wait(1)``), so the
script runs unchanged in the ``auto``, ``lockstep`` and ``realtime`` clocks.

The bus is ``homing_probe.eni`` (two drives that map 6060h/6061h, manual figure 5-1)
and the mechanics ``homing_probe_machine.toml``: axis 1 stands at 80000 below a
"positive" home switch that starts at 100000, with an index pulse every 10000 counts
at 3000 + 10000k.  Method 3 leaves the switch edge moving - and takes the first index
pulse left of it: the axis ends at machine position 93000, where 6064h reads the home
offset (0).  ``GTE_GetMachinePos`` (emulator only) shows where the axis really is.
"""

# the manual's variable names, verbatim (iAxis, xStart, ...)
# ruff: noqa: N815

from __future__ import annotations

import sys
from ctypes import byref, c_double, c_long, c_short, c_ushort
from dataclasses import dataclass
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
ENI = HERE / "homing_probe.eni"
MACHINE = HERE / "homing_probe_machine.toml"


@dataclass
class PlcVars:
    """The VAR block of example 5-2 (plus ``rtn``, which the manual uses undeclared)."""

    iAxis: int = 1
    dwAxisSts: int = 0
    iHomeSts: int = 0
    xStart: bool = False
    xHoming: bool = False
    xStop: bool = False
    rtn: int = 0


def servo_enabled(axis: int) -> bool:
    """``dwAxisSts.9`` of ``GT_GetSts`` (servo enabled); the statusword until GT_GetSts exists."""
    if hasattr(gt, "GT_GetSts"):
        sts = c_long()
        return gt.GT_GetSts(axis, byref(sts), 1, None) == 0 and bool(sts.value & (1 << 9))
    sw = c_ushort()
    return gt.GT_GetEcatAxisPdoData(axis, 0x6041, byref(sw)) == 0 and sw.value & 0x6F == 0x27


def plc_prg(v: PlcVars) -> None:
    """One scan of example 5-2."""
    if v.xStart:
        # start homing
        if servo_enabled(v.iAxis):  # must be servo-enabled
            v.rtn = gt.GT_SetHomingMode(v.iAxis, 6)  # switch to homing mode
            v.rtn = gt.GT_SetEcatHomingPrm(v.iAxis, 3, 5000, 3000, 100000, 0, 0)
            v.rtn = gt.GT_StartEcatHoming(v.iAxis)
            v.xHoming = True
        v.xStart = False
    # check the homing status
    sts = c_short()
    v.rtn = gt.GT_GetEcatHomingStatus(v.iAxis, byref(sts))
    v.iHomeSts = sts.value
    if v.iHomeSts == 3:  # homing completed
        v.rtn = gt.GT_SetHomingMode(v.iAxis, 8)  # back to position control (CSP)
        v.xHoming = False
    if v.xStop:  # interrupt, stop homing
        v.rtn = gt.GT_StopEcatHoming(v.iAxis)
        v.rtn = gt.GT_SetHomingMode(v.iAxis, 8)
        v.xHoming = False
        v.xStop = False


def bring_up(**options: object) -> None:
    """Manual example 5-5: open, initialise, wait until the bus is ready, start."""
    options.setdefault("log", "")
    check(gt.GT_Open(eni=str(ENI), machine=str(MACHINE), **options), "GT_Open")
    check(gt.GT_InitEcatComm(), "GT_InitEcatComm")
    status = c_short()
    for _ in range(10_000):
        if gt.GT_IsEcatReady(byref(status)) == 0 and status.value == 1:
            break
        gt.GTE_Wait(1)
    check(gt.GT_StartEcatComm(), "GT_StartEcatComm")
    check(gt.GT_Reset(), "GT_Reset")


def check(rtn: int, what: str) -> None:
    if rtn != 0:
        raise SystemExit(gt.GTE_GetLastError() or f"{what} returned {rtn}")


def run(max_scans: int = 60_000, **options: object) -> dict[str, object]:
    """Bring the bus up, enable axis 1, home it as example 5-2 does; what came out."""
    gt.GT_Close()
    bring_up(**options)
    try:
        v = PlcVars()
        check(gt.GT_AxisOn(v.iAxis), "GT_AxisOn")
        v.xStart = True
        plc_prg(v)
        scans = 1
        while v.xHoming and scans < max_scans:
            gt.GTE_Wait(1)  # one PLC scan
            plc_prg(v)
            scans += 1
        enc, machine, clock = c_long(), c_double(), c_long()
        gt.GT_GetEcatEncPos(v.iAxis, byref(enc))
        gt.GTE_GetMachinePos(v.iAxis, byref(machine))
        gt.GT_GetClock(byref(clock))
        mode = c_short()
        gt.GT_GetEcatAxisMode(v.iAxis, byref(mode))
        return {
            "home_status": v.iHomeSts,
            "homing": v.xHoming,
            "encoder": enc.value,
            "machine_position": machine.value,
            "mode": mode.value,
            "clock_ms": clock.value,
            "rtn": v.rtn,
        }
    finally:
        gt.GT_Close()


def main() -> int:
    r = run()
    print(
        f"homing status {r['home_status']} after {r['clock_ms']} ms of controller time; "
        f"encoder (6064h) {r['encoder']}, machine position {r['machine_position']:.1f}, "
        f"mode {r['mode']}"
    )
    return 0 if r["home_status"] == 3 and not r["homing"] else 1


if __name__ == "__main__":
    sys.exit(main())
