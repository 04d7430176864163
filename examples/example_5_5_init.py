"""Manual example 5-5, "EtherCAT initialisation in C or C++", in Python.

    python example_5_5_init.py

The manual's listing is ``example_5_5_init.cpp`` (build and run it with libgts: its first
lines say how); this script makes the same calls through ``from gtecat import gt``:
``GT_Open(CHANNEL_PCI_ECATCH)``, ``GT_InitEcatComm``, ``GT_IsEcatReady`` polled until the bus
is in OP, ``GT_StartEcatComm``, ``GT_Reset``, and ``GT_LoadConfig`` with the path the file has
on the controller's own disk, ``\\hard disk\\CPAC\\GTS800.cfg``.  That path does not exist
here, so the file of that name in the working folder is read (``GTS800.cfg`` beside this
script; the master log says which file it read).  Like the listing, it expects
``Gecat.eni``: here the manual's figure 5-2 bus.
"""

from __future__ import annotations

import os
import sys
from ctypes import byref, c_short
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
ENI = HERE / "manual_fig5_2.eni"


def run(**options: object) -> tuple[int, list[str]]:
    """The listing's calls; GT_LoadConfig's return code and what the master log said of it.
    The listing polls GT_IsEcatReady without waiting: run it in the auto clock (the default),
    where every call lets a little controller time pass, not in lockstep."""
    options.setdefault("log", "")
    gt.GT_Close()
    rtn = gt.GT_Open(gt.CHANNEL_PCI_ECATCH, eni=str(ENI), **options)
    if rtn:
        raise RuntimeError("Not find ecat device")
    try:
        rtn = gt.GT_InitEcatComm()
        if rtn:
            raise RuntimeError("EtherCAT communication error")
        status = c_short()
        while True:  # wait until EtherCAT communication is OK
            rtn = gt.GT_IsEcatReady(byref(status))
            if status.value == 1 and rtn == 0:
                break
        rtn = gt.GT_StartEcatComm()
        rtn = gt.GT_Reset()
        rtn = gt.GT_LoadConfig("\\hard disk\\CPAC\\GTS800.cfg")
        said = [line.split("] ", 1)[-1] for line in gt.GTE_Controller().log.lines]
        return rtn, [line for line in said if "GT_LoadConfig" in line]
    finally:
        gt.GT_Close()


def main() -> int:
    os.chdir(HERE)  # the working folder holds GTS800.cfg, as the listing's execution folder
    rtn, log = run()
    print(f"EtherCAT ready, GT_LoadConfig returned {rtn}")
    for line in log[:2]:
        print("master log:", line.replace(str(HERE), "<folder>"))
    return 0 if rtn == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
