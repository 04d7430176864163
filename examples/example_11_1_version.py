"""Manual example 11-1, "read the controller's firmware version", against the emulator.

    python example_11_1_version.py

The manual's program declares ``pVersion: POINTER TO STRING``, passes its
address (``GT_GetVersion(ADR(pVersion))``) and dereferences it
(``firmwareVersion := pVersion^``): the controller hands back a pointer to its
version string.  Through ctypes that is ``c_char_p`` and ``byref``.  Table 11-3
gives the string's form, 18 digits ``aaa bbbbbb ccc dddddd`` (firmware 1's
version and build date, firmware 2's version and build date).
"""

from __future__ import annotations

import re
import sys
from ctypes import byref, c_char_p, c_short
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
ENI = HERE / "manual_fig5_2.eni"
LOG: list[str] = []
TABLE_11_3 = re.compile(rb"\d{3} ?\d{6} ?\d{3} ?\d{6}")


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


def plc_prg() -> tuple[int, bytes | None]:
    """PROGRAM PLC_PRG of example 11-1: (rtn, firmwareVersion)."""
    pVersion = c_char_p()  # pointer to the version string
    rtn = gt.GT_GetVersion(byref(pVersion))  # read the version
    firmwareVersion = pVersion.value
    return rtn, firmwareVersion


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
        rtn, firmwareVersion = plc_prg()
        commandhandler("GT_GetVersion", rtn)
        return {"rtn": rtn, "version": firmwareVersion, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def main() -> int:
    r = run()
    print(f"GT_GetVersion = {r['rtn']}, firmwareVersion = {r['version']!r}")
    for line in r["errors"]:
        print("error:", line)
    version = r["version"]
    ok = not r["errors"] and version is not None and TABLE_11_3.fullmatch(version) is not None
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
