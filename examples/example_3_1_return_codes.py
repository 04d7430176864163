"""Manual example 3-1, "check that a GTN command executed correctly", against the emulator.

    python example_3_1_return_codes.py

The manual's PLC program reads axis 1's status word through the EtherCAT core
(``GT_GetSts(1,1,ADR(sts),1,0)``: core 1, axis 1 - the GTN form its title names)
and hands the return value to ``commandhandler``, which builds
``'<command> = <code>'`` when the code is not 0 (table 3-1).  ``run`` also calls
it once with an axis the bus does not have, so the handler has a 7 to report.
"""

from __future__ import annotations

import sys
from ctypes import byref, c_long, c_short
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
ENI = HERE / "manual_fig5_2.eni"
LOG: list[str] = []


def commandhandler(command: str, error: int) -> int:
    """FUNCTION commandhandler: errInfo := CONCAT(command, ' = ', error) when error <> 0."""
    errInfo = ""
    if error != 0:
        errInfo = command + " = "
        errInfo = errInfo + str(error)
        LOG.append(errInfo)
    return 0  # the ST function never assigns its INT result


def plc_prg(axis: int = 1) -> tuple[int, int]:
    """PROGRAM PLC_PRG of example 3-1: (rtn, sts)."""
    sts = c_long()  # sts: DWORD <- long *pSts
    rtn = gt.GTN_GetSts(1, axis, byref(sts), 1, 0)
    commandhandler("GT_GetSts", rtn)  # check the return value
    return rtn, sts.value


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


def run(**options: object) -> dict[str, object]:
    LOG.clear()
    gt.GT_Close()
    bring_up(**options)
    try:
        rtn, sts = plc_prg()
        ok = list(LOG)
        bad_rtn, _ = plc_prg(axis=99)  # no axis 99: the handler reports 7
        return {"rtn": rtn, "sts": sts, "errors": ok, "bad_rtn": bad_rtn, "bad": LOG[len(ok) :]}
    finally:
        gt.GT_Close()


def main() -> int:
    r = run()
    print(f"GT_GetSts(1, 1, ...) = {r['rtn']}, sts = 0x{r['sts'] & 0xFFFFFFFF:08X}")
    print(f"axis 99: commandhandler reported {r['bad']}")
    for line in r["errors"]:
        print("error:", line)
    return 0 if not r["errors"] and r["rtn"] == 0 and r["bad"] == ["GT_GetSts = 7"] else 1


if __name__ == "__main__":
    sys.exit(main())
