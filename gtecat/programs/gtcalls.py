"""Which GT functions a motion program may call (manual 10.5, table 10-2), and their prototypes.

A program calls GT functions as an application does, with the prototypes of the
one function table (:mod:`gtecat.gt.table`), and at run time through the very same
registered GT functions, so arguments are checked identically (:mod:`gtecat.gt.program_calls`).

Table 10-2 as printed lists 91 names, several of them twice and in OCR-damaged
spellings (``GT_PrflTrap``, ``GT_SetExtloValue``), and it plainly skips the partner
of many listed functions (``GT_GetPrfVel`` but not ``GT_GetPrfPos``, ``GT_AxisOn``
but not ``GT_AxisOff``); it also predates the EtherCAT functions of chapter 5 that
homing programs need.  So gtecat lets a program call every ``GT_`` function of the
table except the host-side ones below (opening and resetting the controller, bus
bring-up, configuration files, the program and MRAM functions, ``GT_GetVersion``),
plus the two that exist only inside programs:

* ``GT_Delay(unsigned short ms)``: the thread sleeps ``ms`` milliseconds of
  controller time (other threads run meanwhile; the call costs one instruction);
* ``GT_SetDataPage(short page)``: the thread's locals move to data page ``page``
  (10.3.5: "a thread may use several data pages and switch between them"); the
  page must not belong to another thread's binding.

A function of table 10-2 that gtecat does not emulate (``GT_SetDo``, ``GT_GetDi``,
the coordinated-motion ones ...) is a compile error saying so; ``GTE_`` emulator
functions are not callable.
"""

from __future__ import annotations

from functools import cache
from typing import Any

#: table 10-2 as the vendor means it (OCR spellings repaired)
TABLE_10_2: frozenset[str] = frozenset(
    """
    GT_Delay GT_DelayHighPrecision GT_SetDataPage GT_SetDo GT_SetDoBit GT_GetDo GT_GetDi
    GT_GetDiReverseCount GT_SetDiReverseCount GT_SetDac GT_GetDac GT_GetDacValue GT_GetEncPos
    GT_SetTrigger GT_GetTriggerStatus GT_LinkCaptureOffset GT_GetCaptureOffset GT_GetClock
    GT_GetSts GT_AxisOn GT_Stop GT_SynchAxisPos GT_GetSoftLimit GT_GetAxisBand GT_GetPrfVel
    GT_GetPrfMode GT_GetAxisPrfVel GT_GetAxisEncPos GT_GetAxisEncAcc GT_SetControlFilter
    GT_GetControlFilter GT_PrfTrap GT_SetTrapPrm GT_GetTrapPrm GT_PrfJog GT_SetJogPrm
    GT_GetJogPrm GT_PrfGear GT_SetGearMaster GT_GetGearMaster GT_SetGearRatio GT_GetGearRatio
    GT_GearStart GT_ZeroPos GT_SetExtIoValue GT_GetExtIoValue GT_SetExtIoBit GT_GetExtIoBit
    GT_SetPid GT_GetPid GT_Update GT_SetPos GT_GetPos GT_SetVel GT_GetVel GT_CrdStatus
    GT_GetExtAdValue GT_GetExtAdVoltage GT_SetExtDaValue GT_SetExtDaVoltage GT_GetStsExtMdl
    GT_AlarmOff GT_AlarmOn GT_LmtsOn GT_LmtsOff GT_ProfileScale GT_EncScale GT_StepDir
    GT_StepPulse GT_SetMtrBias GT_GetMtrBias GT_SetMtrLmt GT_GetMtrLmt GT_EncSns GT_EncOn
    GT_EncOff GT_SetPosErr GT_GetPosErr GT_SetStopDec GT_GetStopDec GT_LmtSns GT_CtrlMode
    GT_CrdSpace GT_CrdStart GT_SetOverride GT_GetCrdVel
    """.split()
)

#: GT functions of the table that belong to the host, never to a program
HOST_ONLY: frozenset[str] = frozenset(
    """
    GT_Open GT_Close GT_Reset GT_GetVersion GT_LoadConfig GT_InitEcatComm GT_StartEcatComm
    GT_TerminateEcatComm GT_Compile GT_Download GT_GetFunId GT_GetVarId GT_Bind GT_RunThread
    GT_StopThread GT_PauseThread GT_GetThreadSts GT_SetVarValue GT_GetVarValue
    GT_SetMRAMData GT_GetMRAMData GT_StartAccessMRAM GT_StopAccessMRAM GT_GetMRAMStatus
    GT_GetMacAddress
    """.split()
)

#: functions that exist only inside programs (the controller runs them itself)
BUILTIN_PROTOTYPES = r"""
short GT_Delay(unsigned short ms);
short GT_SetDataPage(short page /*0..31*/);
"""


@cache
def gtn_prototype(proto: Any) -> Any:
    """The prototype of ``GTN_x``: ``GT_x``'s with ``short core`` first."""
    from ..gt.table import Param, Proto

    params = (Param("core", "short"), *proto.params)
    return Proto("GTN_" + proto.name[3:], params, by_name={p.name: p for p in params})


def prototype(name: str) -> Any:
    """The prototype a program's call of ``name`` was compiled against."""
    from ..gt.table import FUNCTIONS

    if name.startswith("GTN_"):
        return gtn_prototype(builtins().get("GT_" + name[4:]) or FUNCTIONS["GT_" + name[4:]])
    return builtins().get(name) or FUNCTIONS[name]


@cache
def builtins() -> dict[str, Any]:
    from ..gt.table import parse  # lazy: gtecat.gt imports this package

    return parse(BUILTIN_PROTOTYPES)


class Catalog:
    """What the compiler needs to know of GT functions: prototypes and structures."""

    def lookup(self, name: str) -> tuple[Any | None, str]:
        """``(prototype, "")`` when a program may call ``name``, else ``(None, why)``.

        A ``GTN_x`` twin is callable where ``GT_x`` is, with ``short core`` first.
        """
        if name.startswith("GTN_"):
            proto, why = self.lookup("GT_" + name[4:])
            if proto is None:
                return None, why.replace("GT_" + name[4:], name, 1)
            return gtn_prototype(proto), ""
        b = builtins().get(name)
        if b is not None:
            return b, ""
        from ..gt.table import FUNCTIONS

        proto = FUNCTIONS.get(name)
        if proto is not None and name.startswith("GT_") and name not in HOST_ONLY:
            return proto, ""
        if proto is not None:
            if name.startswith("GTE_"):
                return None, f"{name} is an emulator function; motion programs cannot call it"
            return None, (
                f"{name} belongs to the host application; a motion program cannot call it "
                "(table 10-2)"
            )
        if name in TABLE_10_2:
            return None, (
                f"{name} is callable from motion programs on the vendor's controller "
                "(table 10-2), but gtecat does not emulate it"
            )
        if name.startswith(("GT_", "GTN_")):
            return None, f"unknown GT function {name}"
        return None, (f"unknown function {name}: a motion program calls GT functions only (10.4.1)")

    def struct(self, name: str) -> Any:
        """The ctypes structure ``name`` of ``gtecat.gt`` (KeyError when none)."""
        from .. import gt

        cls = getattr(gt, name, None)
        if cls is None:
            raise KeyError(name)
        return cls


__all__ = [
    "BUILTIN_PROTOTYPES",
    "HOST_ONLY",
    "TABLE_10_2",
    "Catalog",
    "builtins",
    "gtn_prototype",
    "prototype",
]
