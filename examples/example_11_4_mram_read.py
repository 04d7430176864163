"""Manual example 11-4, "read data from the memory": 64 words back from the MRAM (11.8.2).

    python example_11_4_mram_read.py [--mram FILE]

On the rising edge of ``xReadMRAM`` the program starts one read of 64 words
(``GT_StartAccessMRAM(0, 64, 0)``); every scan it reads ``GT_GetMRAMStatus``, and
once it is 1, "read done", fetches the controller's buffer 16 words at a time
(``GT_GetMRAMData``) into ``ReadMramBuf: ARRAY [0..3, 0..15] OF INT``.  Run
``example_11_3_mram_write.py`` first (any process, any time before: the memory is
non-volatile); a store never written reads as zeros.
"""

# ruff: noqa: N803, N815  (the PLC variables keep the manual's names)
from __future__ import annotations

import argparse
import sys
from ctypes import byref, c_short
from dataclasses import dataclass, field

from gtecat import gt

LOG: list[str] = []
WordBuf = c_short * 16


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


class RTrig:
    """IEC 61131-3 R_TRIG: Q is TRUE for one call on a rising CLK."""

    def __init__(self) -> None:
        self.m = False
        self.Q = False

    def __call__(self, CLK: bool) -> None:
        self.Q = CLK and not self.m
        self.m = CLK


@dataclass
class PlcVars:
    rtn: int = 0
    xReadMRAM: bool = False
    ReadMRAMR: RTrig = field(default_factory=RTrig)
    ReadMramBuf: list = field(default_factory=lambda: [WordBuf() for _ in range(4)])
    MramSts: c_short = field(default_factory=c_short)


def plc_prg(v: PlcVars) -> None:
    """One scan of example 11-4's PLC_PRG."""
    v.ReadMRAMR(CLK=v.xReadMRAM)
    if v.xReadMRAM:
        if v.ReadMRAMR.Q:
            v.rtn = gt.GT_StartAccessMRAM(0, 64, 0)  # read 64 words at once
            commandhandler("GT_StartAccessMRAM", v.rtn)
        v.rtn = gt.GT_GetMRAMStatus(byref(v.MramSts))
        commandhandler("GT_GetMRAMStatus", v.rtn)
        if v.MramSts.value == 1:  # read done
            for i in range(4):
                v.rtn = gt.GT_GetMRAMData(i * 16, v.ReadMramBuf[i], 16)
                commandhandler("GT_GetMRAMData", v.rtn)
            v.xReadMRAM = False


def run(max_scans: int = 1000, **options: object) -> dict[str, object]:
    LOG.clear()
    gt.GT_Close()
    options.setdefault("log", "")
    commandhandler("GT_Open", gt.GT_Open(**options))
    try:
        v = PlcVars()
        v.xReadMRAM = True
        scans = 0
        while v.xReadMRAM and scans < max_scans:
            plc_prg(v)
            gt.GTE_Wait(1)
            scans += 1
        words = [list(buf) for buf in v.ReadMramBuf]
        return {"done": not v.xReadMRAM, "words": words, "scans": scans, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mram", help="the MRAM store file (default Gecat.mram / GTECAT_MRAM)")
    args = ap.parse_args(argv)
    options = {"mram": args.mram} if args.mram else {}
    r = run(**options)
    flat = [w for row in r["words"] for w in row]
    print(f"read done: {r['done']}; words 0..63: {sorted(set(flat))} (distinct values)")
    for line in r["errors"]:
        print("error:", line)
    return 0 if r["done"] and not r["errors"] else 1


if __name__ == "__main__":
    sys.exit(main())
