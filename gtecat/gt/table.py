"""The one function table: every GT function's C prototype and pointer contract.

Each line below is a prototype as the vendor header writes it (``short`` return,
``long`` stays ``long``, C++ default arguments), followed by the manual's
chapter-13 entry.  A comment after a parameter states what C cannot say:

* ``in`` / ``out`` / ``inout`` with an element count in brackets: a number, the
  name of another parameter (``out[count]``, ``in[size]``), default ``[1]``;
  ``[?]`` when only the call knows (it checks the room itself);
  a pointer without a word is ``out`` (``const`` makes it ``in``);
* ``opt``: the pointer may be NULL (``None``, ``0``, a NULL ctypes pointer) -
  a ``=NULL`` default says the same;
* ``str``: a NUL-terminated text (``char *`` in), ``outstr[n]``: text the
  function writes, at most ``n`` bytes with the NUL;
* ``mask``: a ``long`` bit mask (0 .. 2^32-1 accepted as well as negative longs);
* ``lo..hi``: the legal range of a scalar (beyond the C type's own range).

Everything that handles arguments reads this table: the Python wrappers'
checks (:mod:`gtecat.gt.args`), and the generated ``gts.h`` and C client stubs
of the native library.  A ``GT_x`` line gives ``GTN_x(short core, ...)`` too;
``GTE_`` lines are the emulator's own functions (no ``GTN_`` twin).
``long`` is the vendor's 32-bit Windows ``long``: values are checked to 32 bits.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

PROTOTYPES = r"""
// chapter 5 / 13: controller, EtherCAT bring-up
short GT_Open(short channel=0, short param=1);                                   // 84
short GT_Close();                                                                // 7
short GT_Reset();                                                                // 96
short GT_GetClock(unsigned long *pClock, unsigned long *pLoop=NULL);             // 33
short GT_GetVersion(char *pVersion /*outstr[64]*/);                              // 78
short GT_InitEcatComm();                                                         // 79
short GT_StartEcatComm();                                                        // 129
short GT_TerminateEcatComm();                                                    // 136
short GT_IsEcatReady(short *pStatus);                                            // 80
short GT_GetEcatSlaves(short *pSlaveCnt, short *pIoSlaveCnt=NULL);              // 45 (+ header)
short GT_GetMcEcatAxisNum(short *pNum);                                          // 56
short GT_GetEcatPdoLength(short *pLength);                                       // header
short GT_GetEcatSlaveInfo(short slave, TSlaveInfo *pInfo);                       // header
short GT_GetEcatRawData(unsigned short offset, unsigned short size, unsigned char *pValue /*out[size]*/);  // 44
short GT_SetEcatRawData(unsigned short offset, unsigned short size, unsigned char *pValue /*in[size]*/);   // 104
short GT_EcatIOReadInput(unsigned short slave, unsigned short offset, unsigned short nSize, unsigned char *pValue /*out[nSize]*/);  // 11 (core first too)
short GT_EcatIOWriteOutput(unsigned short slave, unsigned short offset, unsigned short nSize, unsigned char *pValue /*in[nSize]*/);  // 12 (core first too)
short GT_EcatIOBitWriteOutput(unsigned short slave, unsigned short offset, unsigned short bit /*0..7*/, unsigned char value /*0..1*/);  // header
short GT_EcatIOSynch();                                                          // header
short GT_EcatSDODownload(unsigned short slave_position, unsigned short index, unsigned char subindex, unsigned char *pData /*in[data_size]*/, unsigned long data_size, unsigned long *pAbort_code=NULL);  // 13
short GT_EcatSDOUpload(unsigned short slave_position, unsigned short index, unsigned char subindex, unsigned char *pTarget /*out[target_size]*/, unsigned long target_size, unsigned long *pResult_size=NULL, unsigned long *pAbort_code=NULL);  // 14

// chapter 5.2.2.1-3 / 13: EtherCAT axes, homing, touch probe
short GT_AxisOn(short axis);                                                     // 5
short GT_AxisOff(short axis);                                                    // 4
short GT_SetEcatAxisMode(short axis, short mode);                                // 100
short GT_GetEcatAxisMode(short axis, short *pMode);                              // 39
short GT_GetEcatEncPos(short axis, long *pEncPos);                               // 41
short GT_GetEcatEncVel(short axis, long *pEncVel);                               // 42
short GT_GetEcatAxisPE(short axis, long *pPosErr);                               // 40
short GT_GetEcatAxisDI(short axis, unsigned long *pDi);                          // 37
short GT_GetEcatAxisDO(short axis, unsigned long *pDo);                          // 38
short GT_GetEcatAxisAtITorque(short axis, short *pTorque);                       // 36
short GT_GetEcatAxisAtICurrent(short axis, short *pCur);                         // 35
short GT_GetEcatErrorCode(short axis, unsigned short *pErrorCode);               // header
short GT_SetEcatAxisDO(short axis, unsigned long DoValue);                       // 99
short GT_GetEcatAxisAI(short axis, short channel, short *pValue);                // 34
short GT_SetEcatAxisPT(short axis, short torque);                                // 101
short GT_SetEcatAxisPV(short axis, long velocity);                               // 102
short GT_SetPosScale(short axis, unsigned short scale);                          // 117
short GT_GetPosScale(short axis, unsigned short *pScale);                        // 61
short GT_GetEcatAxisPdoData(short axis, unsigned short object, unsigned char *pData /*out[?]*/);  // header (the object's size)
short GT_SetHomingMode(short axis, short mode);                                  // 112
short GT_SetEcatHomingPrm(short axis, short method, double speed1, double speed2, double acc, long offset, unsigned short probeFunction);  // 103
short GT_StartEcatHoming(short axis);                                            // 130
short GT_StopEcatHoming(short axis);                                             // 133
short GT_GetEcatHomingStatus(short axis, short *pHomingStatus);                  // 43
short GT_SetTouchProbeFunction(short axis, short ProbePrm);                      // 123
short GT_SetTouchProbeFunctionEx(short axis, short Probe1Enable, short Probe1TriggerType, short Probe1TriggerLevel, short Probe2Enable, short Probe2TriggerType, short Probe2TriggerLevel);  // 124
short GT_GetTouchProbeStatus(short axis, unsigned short *probeStatus /*opt*/, long *probe1RiseValue /*opt*/, long *probe1FallValue /*opt*/, long *probe2RiseValue /*opt*/, long *probe2FallValue /*opt*/);  // 73

// chapter 7: profiles, Trap, Jog, positions
short GT_PrfTrap(short profile);                                                 // 90
short GT_PrfJog(short profile);                                                  // 88
short GT_GetPrfMode(short profile, long *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 63
short GT_SetTrapPrm(short profile, TTrapPrm *pPrm /*in*/);                       // 125
short GT_GetTrapPrm(short profile, TTrapPrm *pPrm);                              // 74
short GT_SetPos(short profile, long pos);                                        // 115
short GT_GetPos(short profile, long *pPos);                                      // 59
short GT_SetVel(short profile, double vel);                                      // 127
short GT_GetVel(short profile, double *pVel);                                    // 77
short GT_SetJogPrm(short profile, TJogPrm *pPrm /*in*/);                         // 113
short GT_GetJogPrm(short profile, TJogPrm *pPrm);                                // 55
short GT_Update(long mask /*mask*/);                                             // 137
short GT_Stop(long mask /*mask*/, long option /*mask*/);                         // 131
short GT_GetPrfPos(short profile, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 64
short GT_GetPrfVel(short profile, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 65
short GT_GetPrfAcc(short profile, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 62
short GT_GetAxisPrfPos(short axis, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 31
short GT_GetAxisPrfVel(short axis, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 32
short GT_GetAxisPrfAcc(short axis, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 30
short GT_GetAxisEncPos(short axis, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 27
short GT_GetAxisEncVel(short axis, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 28
short GT_GetAxisEncAcc(short axis, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 26
short GT_GetAxisError(short axis, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 29
short GT_GetEncPos(short encoder, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 46
short GT_GetEncVel(short encoder, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 47
short GT_SetEncPos(short encoder, long encPos);                                  // 105
short GT_SetPrfPos(short profile, long prfPos);                                  // 118
short GT_ZeroPos(short axis, short count=1);                                     // 138
short GT_SynchAxisPos(long mask /*mask*/);                                       // 135

// chapters 6, 9, 11: status, safety, configuration
short GT_GetSts(short axis, long *pSts /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 71
short GT_ClrSts(short axis, short count=1);                                      // 8
short GT_AlarmOn(short axis);                                                    // 3
short GT_AlarmOff(short axis);                                                   // 2
short GT_LmtsOn(short axis, short limitType=-1);                                 // 82
short GT_LmtsOff(short axis, short limitType=-1);                                // 81
short GT_SetSoftLimit(short axis, long positive, long negative);                 // 121 (9.2.2)
short GT_GetSoftLimit(short axis, long *pPositive, long *pNegative);             // 69
short GT_SetPosErr(short control, long error);                                   // 116
short GT_GetPosErr(short control, long *pError);                                 // 60
short GT_SetStopDec(short profile, double decSmoothStop, double decAbruptStop);  // 122
short GT_GetStopDec(short profile, double *pDecSmoothStop, double *pDecAbruptStop);  // 70
short GT_SetAxisBand(short axis, long band, long time);                          // 98
short GT_GetAxisBand(short axis, long *pBand, long *pTime);                      // 25
short GT_ProfileScale(short axis, short alpha, short beta);                      // 91
short GT_EncScale(short axis, short alpha, short beta);                          // 17
short GT_EncSns(unsigned short sense);                                           // 18
short GT_EncOn(short encoder);                                                   // 16
short GT_EncOff(short encoder);                                                  // 15
short GT_LoadConfig(char *pFile /*str*/);                                        // 83

// chapter 7.4-7.6: PT, electronic gear, Follow
short GT_PrfPt(short profile, short mode=0);                                     // 89
short GT_PtData(short profile, double pos, long time, short type=0, short fifo=0);  // 93
short GT_PtSpace(short profile, short *pSpace, short fifo=0);                    // 94
short GT_PtClear(short profile, short fifo=0);                                   // 92
short GT_PtStart(long mask /*mask*/, long option=0 /*mask*/);                    // 95
short GT_SetPtLoop(short profile, long loop);                                    // 119
short GT_GetPtLoop(short profile, long *pLoop);                                  // 66
short GT_SetPtMemory(short profile, short memory);                               // 120
short GT_GetPtMemory(short profile, short *pMemory);                             // 67
short GT_GetPtRemainder(short profile, long *pRemainder);                        // 68
short GT_PrfGear(short profile, short dir=0);                                    // 87
short GT_SetGearMaster(short profile, short masterIndex, short masterType=2, short masterItem=0);  // 110
short GT_GetGearMaster(short profile, short *pMasterIndex, short *pMasterType /*opt*/, short *pMasterItem /*opt*/);  // 53
short GT_SetGearRatio(short profile, long masterEven, long slaveEven, long masterSlope=0);  // 111
short GT_GetGearRatio(short profile, long *pMasterEven, long *pSlaveEven, long *pMasterSlope /*opt*/);  // 54
short GT_GearStart(long mask /*mask*/);                                          // 24
short GT_PrfFollow(short profile, short dir=0);                                  // 86
short GT_SetFollowMaster(short profile, short masterIndex, short masterType=2, short masterItem=0);  // 108
short GT_GetFollowMaster(short profile, short *pMasterIndex, short *pMasterType /*opt*/, short *pMasterItem /*opt*/);  // 50
short GT_SetFollowLoop(short profile, long loop);                                // 107
short GT_GetFollowLoop(short profile, long *pLoop);                              // 49
short GT_SetFollowEvent(short profile, short event, short masterDir=1, long pos=0);  // 106
short GT_GetFollowEvent(short profile, short *pEvent, short *pMasterDir /*opt*/, long *pPos /*opt*/);  // 48
short GT_FollowData(short profile, long masterSegment, double slaveSegment, short type=0, short fifo=0);  // 20
short GT_FollowSpace(short profile, short *pSpace, short fifo=0);                // 21
short GT_FollowClear(short profile, short fifo=0);                               // 19
short GT_FollowStart(long mask /*mask*/, long option=0 /*mask*/);                // 22
short GT_FollowSwitch(long mask /*mask*/);                                       // 23
short GT_SetFollowMemory(short profile, short memory);                           // 109
short GT_GetFollowMemory(short profile, short *pMemory);                         // 51

// chapter 10 / 11.8 / 12: motion programs, MRAM, MAC address
short GT_Compile(char *pFileName /*str*/, TCompileInfo *pWrongInfo);              // 9
short GT_Download(char *pFileName /*str*/);                                      // 10
short GT_GetFunId(char *pFunName /*str*/, short *pFunId);                        // 52
short GT_GetVarId(char *pFunName /*str opt*/, char *pVarName /*str*/, TVarInfo *pVarInfo);  // 75
short GT_Bind(short thread /*0..31*/, short funId, short page /*0..31*/);       // 6
short GT_RunThread(short thread /*0..31*/);                                      // 97
short GT_StopThread(short thread /*0..31*/);                                     // 134
short GT_PauseThread(short thread /*0..31*/);                                    // 85
short GT_GetThreadSts(short thread /*0..31*/, TThreadSts *pThreadSts);           // 72
short GT_SetVarValue(short page /*-1..31*/, TVarInfo *pVarInfo /*in*/, double *pValue /*in[count]*/, short count=1 /*1..6*/);  // 126
short GT_GetVarValue(short page /*-1..31*/, TVarInfo *pVarInfo /*in*/, double *pValue /*out[count]*/, short count=1 /*1..6*/);  // 76
short GT_SetMRAMData(short address /*0..4095*/, short *pData /*in[count]*/, short count /*1..24*/);  // 114
short GT_GetMRAMData(short address /*0..4095*/, short *pData /*out[count]*/, short count /*1..24*/);  // 57
short GT_StartAccessMRAM(short address /*0..4095*/, short count /*1..4096*/, short mode /*0..1*/);  // 128
short GT_StopAccessMRAM();                                                       // 132
short GT_GetMRAMStatus(short *pSts);                                             // 58
short GetMacAddress(unsigned long ulAdapterNumber, unsigned char *pMacAddress /*out[ulAddressSize]*/, unsigned long ulAddressSize);  // 1 (chapter 12)
short GT_GetMacAddress(unsigned long ulAdapterNumber, unsigned char *pMacAddress /*out[ulAddressSize]*/, unsigned long ulAddressSize);  // 1 (chapter 12, the GT_ spelling)

// emulator only (no GTN_ twin)
short GTE_Wait(double ms /*0..86400000*/);
short GTE_UnplugSlave(short slave);
short GTE_ReplugSlave(short slave);
short GTE_GetMachinePos(short axis, double *pValue);
short GTE_SetProgramSpeed(double instructionsPerMs /*1..10000000*/);
short GTE_GetThreadError(short thread /*0..31*/, char *pText /*outstr[256]*/);

// coordinated motion (interpolation): coordinate systems, segment FIFOs, look-ahead (header)
short GT_SetCrdPrm(short crd /*1..2*/, TCrdPrm *pCrdPrm /*in*/);                 // header
short GT_GetCrdPrm(short crd /*1..2*/, TCrdPrm *pCrdPrm);                        // header
short GT_CrdSpace(short crd /*1..2*/, long *pSpace, short fifo=0 /*0..1*/);      // header (table 10-2)
short GT_CrdClear(short crd /*1..2*/, short fifo /*0..1*/);                       // header
short GT_LnXY(short crd /*1..2*/, long x, long y, double synVel, double synAcc, double velEnd=0, short fifo=0 /*0..1*/);  // header
short GT_LnXYZ(short crd /*1..2*/, long x, long y, long z, double synVel, double synAcc, double velEnd=0, short fifo=0 /*0..1*/);  // header
short GT_LnXYZA(short crd /*1..2*/, long x, long y, long z, long aPos, double synVel, double synAcc, double velEnd=0, short fifo=0 /*0..1*/);  // header (the vendor names it a: our C stubs use a)
short GT_LnXYG0(short crd /*1..2*/, long x, long y, double synVel, double synAcc, short fifo=0 /*0..1*/);  // header
short GT_ArcXYR(short crd /*1..2*/, long x, long y, double radius, short circleDir /*0..1*/, double synVel, double synAcc, double velEnd=0, short fifo=0 /*0..1*/);  // header
short GT_ArcXYC(short crd /*1..2*/, long x, long y, double xCenter, double yCenter, short circleDir /*0..1*/, double synVel, double synAcc, double velEnd=0, short fifo=0 /*0..1*/);  // header
short GT_ArcYZR(short crd /*1..2*/, long y, long z, double radius, short circleDir /*0..1*/, double synVel, double synAcc, double velEnd=0, short fifo=0 /*0..1*/);  // header
short GT_ArcYZC(short crd /*1..2*/, long y, long z, double yCenter, double zCenter, short circleDir /*0..1*/, double synVel, double synAcc, double velEnd=0, short fifo=0 /*0..1*/);  // header
short GT_ArcZXR(short crd /*1..2*/, long z, long x, double radius, short circleDir /*0..1*/, double synVel, double synAcc, double velEnd=0, short fifo=0 /*0..1*/);  // header
short GT_ArcZXC(short crd /*1..2*/, long z, long x, double zCenter, double xCenter, short circleDir /*0..1*/, double synVel, double synAcc, double velEnd=0, short fifo=0 /*0..1*/);  // header
short GT_HelixXYRZ(short crd /*1..2*/, long x, long y, long z, double radius, short circleDir /*0..1*/, double synVel, double synAcc, double velEnd=0, short fifo=0 /*0..1*/);  // header
short GT_HelixXYCZ(short crd /*1..2*/, long x, long y, long z, double xCenter, double yCenter, short circleDir /*0..1*/, double synVel, double synAcc, double velEnd=0, short fifo=0 /*0..1*/);  // header
short GT_BufIO(short crd /*1..2*/, unsigned short doType, unsigned short doMask, unsigned short doValue, short fifo=0 /*0..1*/);  // header
short GT_BufDelay(short crd /*1..2*/, unsigned short delayTime, short fifo=0 /*0..1*/);  // header
short GT_BufMove(short crd /*1..2*/, short moveAxis, long pos, double vel, double acc, short modal /*0..1*/, short fifo=0 /*0..1*/);  // header
short GT_CrdStart(short mask, short option);                                     // header (table 10-2)
short GT_CrdStatus(short crd /*1..2*/, short *pRun, long *pSegment, short fifo=0 /*0..1*/);  // header (table 10-2)
short GT_GetCrdPos(short crd /*1..2*/, double *pPos /*out[?]*/);                  // header (dimension values)
short GT_GetCrdVel(short crd /*1..2*/, double *pSynVel);                         // header (table 10-2)
short GT_SetOverride(short crd /*1..2*/, double synVelRatio /*0..2*/);           // header (table 10-2)
short GT_SetCrdStopDec(short crd /*1..2*/, double decSmoothStop, double decAbruptStop);  // header
short GT_GetCrdStopDec(short crd /*1..2*/, double *pDecSmoothStop, double *pDecAbruptStop);  // header
short GT_InitLookAhead(short crd /*1..2*/, short fifo /*0..1*/, double T, double accMax, short n /*1..32767*/, TCrdData *pLookAheadBuf /*opt*/);  // header

// GTS pulse card: card IO, encoder capture, smart home (vendor GTS header)
short GT_GetDi(short diType, long *pValue);                                      // header (GTS)
short GT_GetDiRaw(short diType, long *pValue);                                   // header (GTS)
short GT_SetDo(short doType, long value);                                        // header (GTS)
short GT_SetDoBit(short doType, short doIndex, short value /*0..1*/);            // header (GTS)
short GT_GetDo(short doType, long *pValue);                                      // header (GTS)
short GT_SetCaptureMode(short encoder, short mode /*0..3*/);                     // header (GTS)
short GT_GetCaptureMode(short encoder, short *pMode /*out[count]*/, short count=1);  // header (GTS)
short GT_GetCaptureStatus(short encoder, short *pStatus /*out[count]*/, long *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // header (GTS)
short GT_SetCaptureSense(short encoder, short mode /*1..3*/, short sense /*0..1*/);  // header (GTS)
short GT_ClearCaptureStatus(short encoder);                                      // header (GTS)
short GT_GoHome(short axis, THomePrm *pHomePrm /*in*/);                          // header (GTS smart home)
short GT_GetHomePrm(short axis, THomePrm *pHomePrm);                             // header (GTS smart home)
short GT_GetHomeStatus(short axis, THomeStatus *pHomeStatus);                    // header (GTS smart home)
short GTE_SetGpi(short gpi /*1..16*/, short value /*0..1*/);
"""

#: C scalar types: (ctypes name, lo, hi, is_float); ``long`` is the vendor's 32-bit long
SCALARS: dict[str, tuple[str, int, int, bool]] = {
    "char": ("c_char", -128, 127, False),
    "unsigned char": ("c_ubyte", 0, 0xFF, False),
    "short": ("c_short", -(1 << 15), (1 << 15) - 1, False),
    "unsigned short": ("c_ushort", 0, 0xFFFF, False),
    "int": ("c_int", -(1 << 31), (1 << 31) - 1, False),
    "long": ("c_long", -(1 << 31), (1 << 31) - 1, False),
    "unsigned long": ("c_ulong", 0, (1 << 32) - 1, False),
    "double": ("c_double", 0, 0, True),
}


@dataclass(frozen=True, slots=True)
class Param:
    """One parameter of a prototype."""

    name: str
    ctype: str  #: base C type without ``*`` / ``const`` ("unsigned long", "TTrapPrm")
    pointer: bool = False
    direction: str = "in"  #: "in" | "out" | "inout" (scalars are "in")
    count: int | str = 1  #: elements behind the pointer: a number or another parameter's name
    optional: bool = False  #: pointer may be NULL
    text: bool = False  #: NUL-terminated text (``str`` / ``outstr``)
    mask: bool = False
    lo: float | None = None
    hi: float | None = None
    default: str | None = None  #: the C++ default as written ("1", "NULL", "-1")
    comment: str = ""  #: the annotation as written, for the header

    @property
    def is_float(self) -> bool:
        return not self.pointer and self.ctype in ("double", "float")

    @property
    def is_struct(self) -> bool:
        return self.ctype not in SCALARS and self.ctype != "void"

    def default_value(self) -> int | float | None:
        """The default as a Python value (``NULL`` -> None); KeyError when there is none."""
        if self.default is None:
            raise KeyError(self.name)
        if self.default == "NULL":
            return None
        return float(self.default) if self.is_float else int(self.default, 0)


#: ``GT_x`` lines whose ``GTN_x`` twin has no core, as the vendor's GTN header declares
#: them: ``GTN_Open(short channel=5, short param=1)`` and ``GTN_Close(void)`` open and
#: close the whole controller (every core); their parameters with the vendor defaults
NO_CORE_TWINS: dict[str, tuple[tuple[str, str], ...]] = {
    "GT_Open": (("channel", "5"), ("param", "1")),
    "GT_Close": (),
}


@dataclass(frozen=True, slots=True)
class Proto:
    """One GT function as the table declares it."""

    name: str
    params: tuple[Param, ...]
    entry: str = ""  #: the manual's chapter-13 entry (or "header")
    core_first_form: bool = False  #: the manual also prints it with the core first (5.2.2.5)
    by_name: dict[str, Param] = field(default_factory=dict, compare=False, repr=False)

    @property
    def gtn(self) -> bool:
        return self.name.startswith("GT_")

    def c_signature(self, *, defaults: bool, core: bool = False) -> str:
        """The prototype for ``gts.h`` (``core``: the ``GTN_`` twin).

        An input text (``str``) is ``const char *`` where the vendor writes ``char *``: the
        same ABI, and C++ callers passing a string literal (``GT_LoadConfig("GTS800.cfg")``,
        seed 002) compile without ISO C++'s string-constant warning."""
        name = ("GTN_" + self.name[3:]) if core else self.name
        if core and self.name in NO_CORE_TWINS:
            own = [
                f"short {n}={d}" if defaults else f"short {n}" for n, d in NO_CORE_TWINS[self.name]
            ]
            return f"short {name}({', '.join(own) or 'void'})"
        parts = ["short core"] if core else []
        for p in self.params:
            ctype = f"const {p.ctype}" if p.text and p.direction == "in" else p.ctype
            s = f"{ctype} *{p.name}" if p.pointer else f"{ctype} {p.name}"
            if defaults and p.default is not None:
                s += f"={p.default}"
            parts.append(s)
        return f"short {name}({', '.join(parts)})"


_LINE = re.compile(r"^short\s+(\w+)\s*\((.*)\)\s*;\s*(?://\s*(.*))?$")
_PARAM = re.compile(
    r"^(?P<const>const\s+)?(?P<type>(?:unsigned\s+)?\w+)\s*(?P<ptr>\*)?\s*(?P<name>\w+)"
    r"\s*(?:=\s*(?P<default>[\w.+-]+))?\s*(?:/\*(?P<note>[^*]*)\*/)?$"
)
_COUNT = re.compile(r"^(in|out|inout|outstr)(?:\[(\w+|\?)\])?$")
_RANGE = re.compile(r"^(-?[\d.]+)\.\.(-?[\d.]+)$")


def _param(text: str, where: str) -> Param:
    m = _PARAM.match(re.sub(r"\s+", " ", text.strip()))
    if not m:
        raise ValueError(f"{where}: cannot read parameter {text!r}")
    ctype = re.sub(r"\s+", " ", m["type"])
    pointer = bool(m["ptr"])
    note = (m["note"] or "").split()
    kw: dict = {"default": m["default"], "comment": m["note"] or ""}
    if pointer:
        kw["direction"] = "in" if m["const"] else "out"
        kw["optional"] = m["default"] == "NULL"
    for word in note:
        if c := _COUNT.match(word):
            kind, count = c.groups()
            kw["direction"] = "out" if kind == "outstr" else kind
            kw["text"] = kind == "outstr"
            if count is not None:
                kw["count"] = 0 if count == "?" else int(count) if count.isdigit() else count
        elif word == "opt":
            kw["optional"] = True
        elif word == "str":
            kw["text"], kw["direction"] = True, "in"
        elif word == "mask":
            kw["mask"] = True
        elif r := _RANGE.match(word):
            kw["lo"], kw["hi"] = float(r[1]), float(r[2])
        else:
            raise ValueError(f"{where}: unknown annotation {word!r}")
    if not pointer and ctype not in SCALARS:
        raise ValueError(f"{where}: scalar type {ctype!r} unknown")
    return Param(m["name"], ctype, pointer, **kw)


def parse(text: str) -> dict[str, Proto]:
    """The prototypes of ``text`` by name (ValueError names the line it cannot read)."""
    out: dict[str, Proto] = {}
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line or line.startswith("//"):
            continue
        m = _LINE.match(line)
        if not m:
            raise ValueError(f"table line {lineno}: not a prototype: {line!r}")
        name, args, comment = m[1], m[2].strip(), (m[3] or "").strip()
        params = tuple(
            _param(a, f"table line {lineno} ({name})") for a in _split(args) if a.strip()
        )
        names = {p.name for p in params}
        for p in params:
            if isinstance(p.count, str) and p.count not in names:
                raise ValueError(f"table line {lineno}: {p.name} counts by unknown {p.count!r}")
        if name in out:
            raise ValueError(f"table line {lineno}: {name} declared twice")
        out[name] = Proto(
            name,
            params,
            entry=comment,
            core_first_form="core first" in comment,
            by_name={p.name: p for p in params},
        )
    return out


def _split(args: str) -> list[str]:
    """Split a parameter list at commas outside comments."""
    parts, depth, cur = [], 0, []
    i = 0
    while i < len(args):
        if args.startswith("/*", i):
            depth += 1
        elif args.startswith("*/", i):
            depth -= 1
        if args[i] == "," and depth == 0:
            parts.append("".join(cur))
            cur = []
        else:
            cur.append(args[i])
        i += 1
    parts.append("".join(cur))
    return parts


FUNCTIONS: dict[str, Proto] = parse(PROTOTYPES)

__all__ = ["FUNCTIONS", "PROTOTYPES", "SCALARS", "Param", "Proto", "parse"]
