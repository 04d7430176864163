"""Manual example 5-3, "probe 1 rising edge, continuous capture (GTHD)", as a Python script.

    python example_5_3_probe.py

:func:`plc_prg` is the manual's Structured Text program, run once per PLC scan
(1 ms of controller time, ``GTE_Wait(1)``).  A captured status bit stays set until
the probe is switched off (5.2.2.3), so in continuous mode the program tells a new
capture by status bit 6, which the drive toggles on every new probe 1 rising-edge
value (GTHD's refresh flag), against the last state it saw (``xPreSts``).

The bus is ``homing_probe.eni``; axis 2 of ``homing_probe_machine.toml`` has a probe
mark 200 counts wide every 5000 counts with rising edges at 10037.3, 15037.3, ...
45037.3.  The script sweeps the axis across them in cyclic synchronous velocity
(``GT_SetEcatAxisMode(axis, 9)``, ``GT_SetEcatAxisPV``) and collects ``diLastValue``
each time bit 6 changes: the encoder position at each edge, interpolated inside the
cycle in which the axis crossed it (within one count of the true edge).
"""

# the manual's variable names, verbatim (iAxis, xStart, ...)
# ruff: noqa: N815

from __future__ import annotations

import sys
from ctypes import byref, c_long, c_short, c_ushort
from dataclasses import dataclass, field
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
ENI = HERE / "homing_probe.eni"
MACHINE = HERE / "homing_probe_machine.toml"
#: sweep speed, drive counts/s (14.2 counts per 1 ms cycle: edges fall between samples)
SPEED = 14_200
END_POSITION = 47_000


@dataclass
class PlcVars:
    """The VAR block of example 5-3 (``captures`` collects every new ``diLastValue``)."""

    iAxis: int = 2
    xStartProbe: bool = False
    xStopProbe: bool = False
    iProbePrm: int = 0
    uiProbeSts: int = 0
    diRiseValue1: int = 0
    diFallValue1: int = 0
    diRiseValue2: int = 0
    diFallValue2: int = 0
    diLastValue: int = 0
    xPreSts: bool = False
    rtn: int = 0
    captures: list[int] = field(default_factory=list)


def plc_prg(v: PlcVars) -> None:
    """One scan of example 5-3."""
    if v.xStartProbe:
        v.iProbePrm = 0x0013  # probe 1 rising edge, continuous; probe 2 off
        v.rtn = gt.GT_SetTouchProbeFunction(v.iAxis, v.iProbePrm)
        v.xStartProbe = False
    if v.xStopProbe:
        v.iProbePrm = 0x00  # stop capturing
        v.rtn = gt.GT_SetTouchProbeFunction(v.iAxis, v.iProbePrm)
        v.xStopProbe = False

    sts = c_ushort()
    r1, f1, r2, f2 = c_long(), c_long(), c_long(), c_long()
    v.rtn = gt.GT_GetTouchProbeStatus(
        v.iAxis, byref(sts), byref(r1), byref(f1), byref(r2), byref(f2)
    )
    v.uiProbeSts = sts.value
    v.diRiseValue1, v.diFallValue1 = r1.value, f1.value
    v.diRiseValue2, v.diFallValue2 = r2.value, f2.value
    if v.uiProbeSts & (1 << 0):  # probe 1 enabled
        if v.uiProbeSts & (1 << 1):  # probe 1 rising edge captured
            bit6 = bool(v.uiProbeSts & (1 << 6))
            if bit6 != v.xPreSts:  # a new capture: GTHD toggles bit 6
                v.diLastValue = v.diRiseValue1
                v.xPreSts = bit6
                v.captures.append(v.diLastValue)
        if v.uiProbeSts & (1 << 2):  # probe 1 falling edge captured
            pass
    if v.uiProbeSts & (1 << 8):  # probe 2 enabled
        pass


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


def run(speed: int = SPEED, max_scans: int = 60_000, **options: object) -> dict[str, object]:
    """Arm probe 1, sweep axis 2 across the marks, stop the probe; what was captured."""
    gt.GT_Close()
    bring_up(**options)
    try:
        v = PlcVars()
        check(gt.GT_AxisOn(v.iAxis), "GT_AxisOn")
        v.xStartProbe = True
        plc_prg(v)
        check(gt.GT_SetEcatAxisMode(v.iAxis, 9), "GT_SetEcatAxisMode")  # CSV
        check(gt.GT_SetEcatAxisPV(v.iAxis, speed), "GT_SetEcatAxisPV")
        enc = c_long()
        scans = 0
        while scans < max_scans:
            gt.GTE_Wait(1)  # one PLC scan
            plc_prg(v)
            scans += 1
            gt.GT_GetEcatEncPos(v.iAxis, byref(enc))
            if enc.value >= END_POSITION:
                break
        check(gt.GT_SetEcatAxisPV(v.iAxis, 0), "GT_SetEcatAxisPV")
        gt.GTE_Wait(100)
        v.xStopProbe = True
        plc_prg(v)
        status_after_stop = v.uiProbeSts
        check(gt.GT_SetEcatAxisMode(v.iAxis, 8), "GT_SetEcatAxisMode")  # back to CSP
        return {
            "captures": list(v.captures),
            "last_value": v.diLastValue,
            "status_after_stop": status_after_stop,
            "encoder": enc.value,
            "rtn": v.rtn,
        }
    finally:
        gt.GT_Close()


def main() -> int:
    r = run()
    print(f"probe 1 rising edges captured: {r['captures']}")
    print(f"status after GT_SetTouchProbeFunction(axis, 0): 0x{r['status_after_stop']:04X}")
    return 0 if r["captures"] else 1


if __name__ == "__main__":
    sys.exit(main())
