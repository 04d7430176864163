"""Manual example 10-2, "multi-thread sum": two threads of one function share the work.

    python example_10_2_two_threads.py [--keep DIR]

The motion program is the one of example 10-1 (``example_10_1_sum.c``).  Thread 0
runs ``add`` on data page 0 with begin = 1, end = 50; thread 1 runs the same
function on page 1 with begin = 51, end = 100; both add into the global ``sum``.
Each thread's locals are its own (one page each, 10.3.5) while ``sum`` is shared;
the threads interleave instruction by instruction, and ``sum = sum + i`` is one
instruction, so no addition is lost: 5050 again.  The two threads share the
controller's 100 instructions per millisecond, so together (2 x 254 instructions)
they take about as long as example 10-1's single thread (504).
"""

# ruff: noqa: N815  (the PLC variables keep the manual's names)
from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
from ctypes import byref, c_double, c_short
from dataclasses import dataclass, field
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
SOURCE = HERE / "example_10_1_sum.c"  # "the motion program is the one of example 10-1"
LOG: list[str] = []


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


@dataclass
class PlcVars:
    """The VAR block of example 10-2 (one TThreadSts per thread here, to keep both)."""

    xInitDone: bool = False
    rtn: int = 0
    sDownloadFileName: str = "sum.bin"
    sFunname: str = "add"
    sVvarname: str = "sum"
    funId: c_short = field(default_factory=c_short)
    sum: gt.TVarInfo = field(default_factory=gt.TVarInfo)
    begin: gt.TVarInfo = field(default_factory=gt.TVarInfo)
    end: gt.TVarInfo = field(default_factory=gt.TVarInfo)
    value: c_double = field(default_factory=c_double)
    thread: gt.TThreadSts = field(default_factory=gt.TThreadSts)
    thread1: gt.TThreadSts = field(default_factory=gt.TThreadSts)


def set_var(page: int, var: gt.TVarInfo, v: PlcVars, value: float) -> None:
    v.value.value = value
    v.rtn = gt.GT_SetVarValue(page, byref(var), byref(v.value), 1)
    commandhandler("GT_SetVarValue", v.rtn)


def plc_prg(v: PlcVars) -> None:
    """One scan of example 10-2's PLC_PRG."""
    if not v.xInitDone:
        v.rtn = gt.GT_Download(v.sDownloadFileName)
        commandhandler("GT_Download", v.rtn)
        v.rtn = gt.GT_GetFunId(v.sFunname, byref(v.funId))
        commandhandler("GT_GetFunId", v.rtn)
        commandhandler("GT_GetVarId", gt.GT_GetVarId(0, "sum", byref(v.sum)))
        commandhandler("GT_GetVarId", gt.GT_GetVarId(v.sFunname, "begin", byref(v.begin)))
        commandhandler("GT_GetVarId", gt.GT_GetVarId(v.sFunname, "end", byref(v.end)))
        commandhandler("GT_Bind", gt.GT_Bind(0, v.funId.value, 0))  # thread 0 on page 0
        commandhandler("GT_Bind", gt.GT_Bind(1, v.funId.value, 1))  # thread 1 on page 1
        set_var(-1, v.sum, v, 0)  # the global sum
        set_var(0, v.begin, v, 1)  # thread 0 adds 1..50
        set_var(0, v.end, v, 50)
        set_var(1, v.begin, v, 51)  # thread 1 adds 51..100
        set_var(1, v.end, v, 100)
        commandhandler("GT_RunThread", gt.GT_RunThread(0))
        commandhandler("GT_RunThread", gt.GT_RunThread(1))
        v.xInitDone = True
    v.rtn = gt.GT_GetThreadSts(0, byref(v.thread))
    v.rtn = gt.GT_GetThreadSts(1, byref(v.thread1))
    v.rtn = gt.GT_GetVarValue(-1, byref(v.sum), byref(v.value), 1)


def run(workdir: Path, max_scans: int = 1000, **options: object) -> dict[str, object]:
    LOG.clear()
    gt.GT_Close()
    options.setdefault("log", "")
    commandhandler("GT_Open", gt.GT_Open(**options))
    try:
        shutil.copyfile(SOURCE, workdir / "sum.c")
        info = gt.TCompileInfo()
        commandhandler("GT_Compile", gt.GT_Compile(str(workdir / "sum.c"), byref(info)))
        v = PlcVars()
        scans, finished = 0, {}
        here = Path.cwd()
        try:
            os.chdir(workdir)
            plc_prg(v)
            while scans < max_scans:
                gt.GTE_Wait(1)
                plc_prg(v)
                scans += 1
                for n, th in ((0, v.thread), (1, v.thread1)):
                    if th.run == 0 and n not in finished:
                        finished[n] = scans
                if len(finished) == 2:
                    break
        finally:
            os.chdir(here)
        return {
            "sum": v.value.value,
            "results": (v.thread.result, v.thread1.result),
            "finished_ms": (finished.get(0), finished.get(1)),
            "errors": list(LOG),
        }
    finally:
        gt.GT_Close()


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--keep", help="compile into this directory and keep sum.bin / sum.ini")
    args = ap.parse_args(argv)
    if args.keep:
        Path(args.keep).mkdir(parents=True, exist_ok=True)
        r = run(Path(args.keep))
    else:
        with tempfile.TemporaryDirectory() as tmp:
            r = run(Path(tmp))
    print(f"sum = {r['sum']:g}; threads ended after {r['finished_ms']} ms")
    for line in r["errors"]:
        print("error:", line)
    return 0 if not r["errors"] and r["sum"] == 5050 else 1


if __name__ == "__main__":
    sys.exit(main())
