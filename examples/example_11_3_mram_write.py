"""Manual example 11-3, "write data to the memory": 64 words into the MRAM (11.8.1).

    python example_11_3_mram_write.py [--mram FILE] [--value 12345]

``WriteMramBuf: ARRAY [0..3, 0..15] OF INT := 12345``: on the rising edge of
``xWriteMRAM`` the program sends the buffer to the controller 16 words at a time
(``GT_SetMRAMData``, at most 24 per call) and starts one write of 64 words
(``GT_StartAccessMRAM(0, 64, 1)``); every scan it reads ``GT_GetMRAMStatus`` until
1, "write done".  The memory is non-volatile: ``example_11_4_mram_read.py`` reads
the words back, in another process.  The store is ``--mram FILE`` (default
``Gecat.mram`` in the working directory, or ``GTECAT_MRAM``).
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
    xWriteMRAM: bool = False
    WriteMRAMR: RTrig = field(default_factory=RTrig)
    WriteMramBuf: list = field(default_factory=lambda: [WordBuf(*[12345] * 16) for _ in range(4)])
    MramSts: c_short = field(default_factory=c_short)


def plc_prg(v: PlcVars) -> None:
    """One scan of example 11-3's PLC_PRG."""
    v.WriteMRAMR(CLK=v.xWriteMRAM)
    if v.xWriteMRAM:
        if v.WriteMRAMR.Q:
            for i in range(4):
                v.rtn = gt.GT_SetMRAMData(i * 16, v.WriteMramBuf[i], 16)
                commandhandler("GT_SetMRAMData", v.rtn)
            v.rtn = gt.GT_StartAccessMRAM(0, 64, 1)  # write 64 words at once
            commandhandler("GT_StartAccessMRAM", v.rtn)
        v.rtn = gt.GT_GetMRAMStatus(byref(v.MramSts))
        commandhandler("GT_GetMRAMStatus", v.rtn)
        if v.MramSts.value == 1:  # write done
            v.xWriteMRAM = False


def run(value: int = 12345, max_scans: int = 1000, **options: object) -> dict[str, object]:
    LOG.clear()
    gt.GT_Close()
    options.setdefault("log", "")
    commandhandler("GT_Open", gt.GT_Open(**options))
    try:
        v = PlcVars()
        for buf in v.WriteMramBuf:
            buf[:] = [value] * 16
        v.xWriteMRAM = True
        scans = 0
        while v.xWriteMRAM and scans < max_scans:
            plc_prg(v)
            gt.GTE_Wait(1)
            scans += 1
        return {"done": not v.xWriteMRAM, "scans": scans, "errors": list(LOG)}
    finally:
        gt.GT_Close()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mram", help="the MRAM store file (default Gecat.mram / GTECAT_MRAM)")
    ap.add_argument("--value", type=int, default=12345, help="the value of every word")
    args = ap.parse_args(argv)
    options = {"mram": args.mram} if args.mram else {}
    r = run(args.value, **options)
    print(f"64 words of {args.value} written: {r['done']} (after {r['scans']} scans)")
    for line in r["errors"]:
        print("error:", line)
    return 0 if r["done"] and not r["errors"] else 1


if __name__ == "__main__":
    sys.exit(main())
