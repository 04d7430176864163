"""Manual example 5-4, "using EtherCAT IO", as a Python script.

    python example_5_4_ecat_io.py

The bus is the manual's figure 5-4: one coupler (slave 0) with a DI16, a DO16, an AI4 and an
AO4 module; figure 5-5 gives the byte offsets inside the slave: outputs DO16 at 2, AO4 at
4..11; inputs DI16 at 14, AI4 at 16..23.  :func:`plc_prg` is the manual's program: it reads
the digital inputs, the analogue inputs 1 and 2 one by one and 3-4 together, and writes the
digital outputs and the four analogue outputs.  The manual's listing reads into
``wAInput34`` / writes ``wDOutput`` and ``wAOutput1234`` while its VAR block declares
``arrAInput34``, ``wDOuput`` and ``arrAOutput1234``: the script uses the declared variables.

The script plays the field side as well (``GTE_Slave(0)``: what the modules' terminals
see), sets the inputs, runs one scan and shows what each side read.
"""

# the manual's variable names, verbatim (iSlave, wDInput, ...)
# ruff: noqa: N815

from __future__ import annotations

import sys
from ctypes import byref, c_short, c_ushort
from dataclasses import dataclass, field
from pathlib import Path

from gtecat import gt

HERE = Path(__file__).resolve().parent
ENI = HERE / "manual_fig5_4.eni"
LOG: list[str] = []


def commandhandler(command: str, rtn: int) -> None:
    if rtn != 0:
        LOG.append(gt.GTE_GetLastError() or f"{command} = {rtn}")


@dataclass
class PlcVars:
    """The VAR block of example 5-4 (WORD values as the unsigned 16-bit words they are)."""

    rtn: int = 0
    iSlave: int = 0  # the slave number
    wDInput: int = 0
    wDOuput: int = 0x00A5  # the outputs the program writes (here: a pattern)
    wAInput1: int = 0
    wAInput2: int = 0
    arrAInput34: list[int] = field(default_factory=lambda: [0, 0])
    arrAOutput1234: list[int] = field(default_factory=lambda: [1000, 2000, 3000, 4000])


def plc_prg(v: PlcVars) -> None:
    """One scan of example 5-4."""
    w = c_ushort()
    # read the digital module's inputs
    v.rtn = gt.GT_EcatIOReadInput(v.iSlave, 14, 2, byref(w))
    commandhandler("GT_EcatIOReadInput", v.rtn)
    v.wDInput = w.value
    # read the analogue module's inputs
    v.rtn = gt.GT_EcatIOReadInput(v.iSlave, 16, 2, byref(w))
    commandhandler("GT_EcatIOReadInput", v.rtn)
    v.wAInput1 = w.value
    v.rtn = gt.GT_EcatIOReadInput(v.iSlave, 18, 2, byref(w))
    commandhandler("GT_EcatIOReadInput", v.rtn)
    v.wAInput2 = w.value
    both = (c_ushort * 2)()
    v.rtn = gt.GT_EcatIOReadInput(v.iSlave, 20, 4, both)
    commandhandler("GT_EcatIOReadInput", v.rtn)
    v.arrAInput34 = list(both)
    # write the digital module's outputs
    v.rtn = gt.GT_EcatIOWriteOutput(v.iSlave, 2, 2, byref(c_ushort(v.wDOuput)))
    commandhandler("GT_EcatIOWriteOutput", v.rtn)
    # write the analogue module's outputs
    v.rtn = gt.GT_EcatIOWriteOutput(v.iSlave, 4, 8, (c_ushort * 4)(*v.arrAOutput1234))
    commandhandler("GT_EcatIOWriteOutput", v.rtn)


def bring_up(**options: object) -> None:
    """Manual 5.2.1: open, initialise, wait for OP, start."""
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
        coupler = gt.GTE_Slave(0)  # the field side of the four modules
        coupler.set_input(0x6000, 1, 0x0F0F)  # DI16: inputs 1-4 and 9-12 on
        for ch, value in enumerate((0x0100, 0x0200, 0x0300, 0x0400), start=1):
            coupler.set_input(0x6020, ch, value)  # AI4 channels 1..4
        gt.GTE_Wait(2)  # the inputs travel in the next cycle
        v = PlcVars()
        plc_prg(v)
        gt.GTE_Wait(2)  # the outputs too
        return {
            "read": (v.wDInput, v.wAInput1, v.wAInput2, v.arrAInput34),
            "do16": coupler.get_output(0x7010, 1) & 0xFFFF,
            "ao4": [coupler.get_output(0x7030, k) & 0xFFFF for k in range(1, 5)],
            "errors": list(LOG),
        }
    finally:
        gt.GT_Close()


def main() -> int:
    r = run()
    di, ai1, ai2, ai34 = r["read"]
    print(f"program read: wDInput 0x{di:04X}, wAInput1 0x{ai1:04X}, wAInput2 0x{ai2:04X}, "
          f"arrAInput34 {[f'0x{x:04X}' for x in ai34]}")  # fmt: skip
    print(f"the modules got: DO16 0x{r['do16']:04X}, AO4 {r['ao4']}")
    for line in r["errors"]:
        print("error:", line)
    return 0 if not r["errors"] else 1


if __name__ == "__main__":
    sys.exit(main())
