"""Manual example 10-1, "single-thread sum": a motion program adds begin..end into ``sum``.

    python example_10_1_sum.py [--keep DIR]

The motion program is ``example_10_1_sum.c`` beside this script (the manual's
``add``, as printed).  The application compiles it as ``sum.c`` in a work
directory (a temporary one, or ``--keep DIR``) - ``GT_Compile`` writes ``sum.bin``
and ``sum.ini`` there - then does what the manual's PLC program does: download,
function and variable ids, bind thread 0 / function / page 0, sum = 0, begin = 1,
end = 100, run thread 0, and every scan read the thread status and ``sum``.  The
scan repeats every controller millisecond until the thread has returned: 5050,
after about 5 ms (504 instructions at 100 per millisecond).
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
SOURCE = HERE / "example_10_1_sum.c"
LOG: list[str] = []


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


def compile_program(workdir: Path) -> Path:
    """MCT2008's step (10.3.2): sum.c -> sum.bin + sum.ini in ``workdir``."""
    src = workdir / "sum.c"
    shutil.copyfile(SOURCE, src)
    info = gt.TCompileInfo()
    rtn = gt.GT_Compile(str(src), byref(info))
    if rtn != 0:
        raise SystemExit(f"{info.pFileName.decode()}:{info.pLineNo[0]}: {info.pMessage.decode()}")
    return workdir / "sum.bin"


@dataclass
class PlcVars:
    """The VAR block of example 10-1."""

    xInitDone: bool = False
    rtn: int = 0
    sDownloadFileName: str = "sum.bin"
    sFunname: str = "add"
    sVarname: str = "sum"
    funId: c_short = field(default_factory=c_short)
    sum: gt.TVarInfo = field(default_factory=gt.TVarInfo)
    begin: gt.TVarInfo = field(default_factory=gt.TVarInfo)
    end: gt.TVarInfo = field(default_factory=gt.TVarInfo)
    value: c_double = field(default_factory=c_double)
    thread: gt.TThreadSts = field(default_factory=gt.TThreadSts)


def plc_prg(v: PlcVars) -> None:
    """One scan of example 10-1's PLC_PRG."""
    if not v.xInitDone:
        # download sum.bin (it must be in the project folder)
        v.rtn = gt.GT_Download(v.sDownloadFileName)
        commandhandler("GT_Download", v.rtn)
        v.rtn = gt.GT_GetFunId(v.sFunname, byref(v.funId))  # the function id
        commandhandler("GT_GetFunId", v.rtn)
        v.sVarname = "sum"  # the global sum
        v.rtn = gt.GT_GetVarId(0, v.sVarname, byref(v.sum))
        commandhandler("GT_GetVarId", v.rtn)
        v.sVarname = "begin"  # the local begin
        v.rtn = gt.GT_GetVarId(v.sFunname, v.sVarname, byref(v.begin))
        commandhandler("GT_GetVarId", v.rtn)
        v.sVarname = "end"  # the local end
        v.rtn = gt.GT_GetVarId(v.sFunname, v.sVarname, byref(v.end))
        commandhandler("GT_GetVarId", v.rtn)
        v.rtn = gt.GT_Bind(0, v.funId.value, 0)  # thread 0, function, data page 0
        commandhandler("GT_Bind", v.rtn)
        v.value.value = 0
        v.rtn = gt.GT_SetVarValue(-1, byref(v.sum), byref(v.value), 1)  # sum = 0
        commandhandler("GT_SetVarValue", v.rtn)
        v.value.value = 1
        v.rtn = gt.GT_SetVarValue(0, byref(v.begin), byref(v.value), 1)  # begin = 1
        commandhandler("GT_SetVarValue", v.rtn)
        v.value.value = 100
        v.rtn = gt.GT_SetVarValue(0, byref(v.end), byref(v.value), 1)  # end = 100
        commandhandler("GT_SetVarValue", v.rtn)
        v.rtn = gt.GT_RunThread(0)  # start the thread
        commandhandler("GT_RunThread", v.rtn)
        v.xInitDone = True
    v.rtn = gt.GT_GetThreadSts(0, byref(v.thread))  # the thread's status
    v.rtn = gt.GT_GetVarValue(-1, byref(v.sum), byref(v.value), 1)  # sum


def run(workdir: Path, max_scans: int = 1000, **options: object) -> dict[str, object]:
    """Compile, then scan once per controller millisecond until thread 0 has returned."""
    LOG.clear()
    gt.GT_Close()
    options.setdefault("log", "")
    commandhandler("GT_Open", gt.GT_Open(**options))
    try:
        compile_program(workdir)
        v = PlcVars()
        scans = 0
        here = Path.cwd()
        try:
            os.chdir(workdir)  # "sum.bin must be in the project folder"
            plc_prg(v)
            while scans < max_scans:
                gt.GTE_Wait(1)
                plc_prg(v)
                scans += 1
                if v.thread.run == 0:
                    break
        finally:
            os.chdir(here)
        return {
            "sum": v.value.value,
            "result": v.thread.result,
            "run": v.thread.run,
            "error": v.thread.error,
            "line": v.thread.line,
            "scans": scans,
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
    print(
        f"sum = {r['sum']:g} (thread 0 returned {r['result']:g} at line {r['line']}, "
        f"after {r['scans']} ms)"
    )
    for line in r["errors"]:
        print("error:", line)
    return 0 if not r["errors"] and r["sum"] == 5050 else 1


if __name__ == "__main__":
    sys.exit(main())
