"""Manual example 5-1, "read the bus communication state", as a Python script.

    python example_5_1_ecat_status.py

:func:`plc_prg` is the manual's program: every scan it asks ``GT_IsEcatReady`` and returns
early while the bus is not in OP (``iEcatSts <> 1``); only then does the rest of the program
(the manual's ``.....``, here a count of the scans that got that far) run.  The script calls
``GT_InitEcatComm`` and runs one scan per millisecond (``GTE_Wait(1)``) on the manual's
figure 5-2 bus: the first scans return early while the slaves go INIT -> PREOP -> SAFEOP
-> OP, then every scan goes on.
"""

# the manual's variable names, verbatim (rtn, iEcatSts)
# ruff: noqa: N815

from __future__ import annotations

import sys
from ctypes import byref, c_short
from dataclasses import dataclass
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
ENI = HERE / "manual_fig5_2.eni"


@dataclass
class PlcVars:
    """The VAR block of example 5-1, and two counters of the script's own."""

    rtn: int = 0  # the command's return value
    iEcatSts: int = 0  # the EtherCAT bus state
    returned_early: int = 0  # added: scans that stopped at RETURN
    went_on: int = 0  # added: scans that reached the rest of the program


def plc_prg(v: PlcVars) -> None:
    """One scan of example 5-1."""
    sts = c_short()
    v.rtn = gt.GT_IsEcatReady(byref(sts))
    v.iEcatSts = sts.value
    if v.iEcatSts != 1:
        v.returned_early += 1
        return
    v.went_on += 1  # the manual's "....."


def run(scans: int = 200, **options: object) -> PlcVars:
    options.setdefault("log", "")
    gt.GT_Close()
    rc = gt.GT_Open(eni=str(ENI), **options)
    if rc != 0:
        raise RuntimeError(f"GT_Open returned {rc}: {gt.GTE_GetLastError()}")
    try:
        rc = gt.GT_InitEcatComm()
        if rc != 0:
            raise RuntimeError(f"GT_InitEcatComm returned {rc}: {gt.GTE_GetLastError()}")
        v = PlcVars()
        for _ in range(scans):
            plc_prg(v)
            gt.GTE_Wait(1)  # one PLC scan
        return v
    finally:
        gt.GT_Close()


def main() -> int:
    v = run()
    print(f"scans that returned early (bus not in OP): {v.returned_early}")
    print(f"scans that went on: {v.went_on}; last rtn {v.rtn}, iEcatSts {v.iEcatSts}")
    return 0 if v.rtn == 0 and v.iEcatSts == 1 and v.went_on > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
