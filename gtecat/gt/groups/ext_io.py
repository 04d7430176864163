"""Extension IO modules: the GTS ``ExtMdl`` functions, their multi-card ``*Gts`` forms, the GTN
cores' extension modules and gLink-II (vendor GTS / GTN headers, ``gtgl500.h``).

Module ``mdl`` 0..15 and bit ``index`` 0..15 as the vendor numbers them (GTS); the GTN cores
number terminals from 1 across the whole chain; gLink slaves 0..63, bits from 0.  The
``*Gts`` forms take the multi-card wrappers' ``short cardNum`` first.  Implemented by
:mod:`gtecat.gt.ext_io_calls`; the machine description says what is plugged in.
"""

NAME = "ext_io"
TITLE = "extension IO modules (ExtMdl, GTN extension modules, gLink)"

PROTOTYPES = r"""
// extension IO modules, GTS ExtMdl (vendor GTS header)
short GT_OpenExtMdl(char *pDllName=NULL /*str*/);                                // header (ExtMdl)
short GT_CloseExtMdl();                                                          // header (ExtMdl)
short GT_SwitchtoCardNoExtMdl(short card);                                       // header (ExtMdl)
short GT_ResetExtMdl();                                                          // header (ExtMdl)
short GT_LoadExtConfig(char *pFileName /*str*/);                                 // header (ExtMdl)
short GT_SetExtIoValue(short mdl /*0..15*/, unsigned short value);               // header (ExtMdl)
short GT_GetExtIoValue(short mdl /*0..15*/, unsigned short *pValue);             // header (ExtMdl)
short GT_SetExtIoBit(short mdl /*0..15*/, short index /*0..31*/, unsigned short value /*0..1*/);  // header (ExtMdl)
short GT_GetExtIoBit(short mdl /*0..15*/, short index /*0..31*/, unsigned short *pValue);  // header (ExtMdl)
short GT_GetExtAdValue(short mdl /*0..15*/, short chn, unsigned short *pValue);  // header (ExtMdl)
short GT_GetExtAdVoltage(short mdl /*0..15*/, short chn, double *pValue);        // header (ExtMdl)
short GT_SetExtDaValue(short mdl /*0..15*/, short chn, unsigned short value);    // header (ExtMdl)
short GT_SetExtDaVoltage(short mdl /*0..15*/, short chn, double value);          // header (ExtMdl)
short GT_GetStsExtMdl(short mdl /*0..15*/, short chn, unsigned short *pStatus);  // header (ExtMdl)
short GT_GetExtDoValue(short mdl /*0..15*/, unsigned short *pValue);             // header (ExtMdl)
short GT_GetExtMdlMode(short *pMode);                                            // header (ExtMdl)
short GT_SetExtMdlMode(short mode /*0..1*/);                                     // header (ExtMdl)

// the same, multi-card wrappers (cardNum first)
short GT_OpenExtMdlGts(short cardNum, char *pDllName=NULL /*str*/);             // wrapper (multi-card)
short GT_CloseExtMdlGts(short cardNum);                                          // wrapper (multi-card)
short GT_SwitchtoCardNoExtMdlGts(short cardNum, short card);                     // wrapper (multi-card)
short GT_ResetExtMdlGts(short cardNum);                                          // wrapper (multi-card)
short GT_LoadExtConfigGts(short cardNum, char *pFileName /*str*/);               // wrapper (multi-card)
short GT_SetExtIoValueGts(short cardNum, short mdl /*0..15*/, unsigned short value);  // wrapper (multi-card)
short GT_GetExtIoValueGts(short cardNum, short mdl /*0..15*/, unsigned short *pValue);  // wrapper (multi-card)
short GT_SetExtIoBitGts(short cardNum, short mdl /*0..15*/, short index /*0..31*/, unsigned short value /*0..1*/);  // wrapper (multi-card)
short GT_GetExtIoBitGts(short cardNum, short mdl /*0..15*/, short index /*0..31*/, unsigned short *pValue);  // wrapper (multi-card)
short GT_GetExtAdValueGts(short cardNum, short mdl /*0..15*/, short chn, unsigned short *pValue);  // wrapper (multi-card)
short GT_GetExtAdVoltageGts(short cardNum, short mdl /*0..15*/, short chn, double *pValue);  // wrapper (multi-card)
short GT_SetExtDaValueGts(short cardNum, short mdl /*0..15*/, short chn, unsigned short value);  // wrapper (multi-card)
short GT_SetExtDaVoltageGts(short cardNum, short mdl /*0..15*/, short chn, double value);  // wrapper (multi-card)
short GT_GetStsExtMdlGts(short cardNum, short mdl /*0..15*/, short chn, unsigned short *pStatus);  // wrapper (multi-card)
short GT_GetExtDoValueGts(short cardNum, short mdl /*0..15*/, unsigned short *pValue);  // wrapper (multi-card)

// extension modules of the GTN cores (vendor GTN header): terminals numbered from 1 over the chain
short GT_ExtModuleInit(short method=1);                                          // header (GTN)
short GT_SetExtDoBit(short doIndex, short value /*0..1*/);                       // header (GTN)
short GT_GetExtDoBit(short doIndex, short *pValue);                              // header (GTN)
short GT_SetExtDo(short doIndex, long value /*mask*/, long mask /*mask*/);      // header (GTN)
short GT_GetExtDo(short doIndex, long *pValue);                                  // header (GTN)
short GT_GetExtDiBit(short diIndex, short *pValue);                              // header (GTN)
short GT_GetExtDi(short diIndex, long *pValue);                                  // header (GTN)
short GT_SetExtAoValue(short index, short *pValue /*in[count]*/, short count=1);  // header (GTN)
short GT_GetExtAiValue(short index, short *pValue /*out[count]*/, short count=1);  // header (GTN)
short GT_SetExtAo(short index, double *pValue /*in[count]*/, short count=1);      // header (GTN)
short GT_GetExtAo(short index, double *pValue /*out[count]*/, short count=1);     // header (GTN)
short GT_GetExtAi(short index, double *pValue /*out[count]*/, short count=1);     // header (GTN)

// gLink-II extension IO (vendor gtgl500.h): slaves 0..63, bits from 0
short GT_GLinkInit(short cardNum);                                               // header (gLink)
short GT_GetGLinkOnlineSlaveNum(unsigned char *slavenum);                        // header (gLink)
short GT_SetGLinkDo(short slaveno /*0..63*/, unsigned short offset, unsigned char *pData /*in[bytelength]*/, unsigned short bytelength);  // header (gLink)
short GT_GetGLinkDo(short slaveno /*0..63*/, unsigned short offset, unsigned char *pData /*out[bytelength]*/, unsigned short bytelength);  // header (gLink)
short GT_GetGLinkDi(short slaveno /*0..63*/, unsigned short offset, unsigned char *pData /*out[bytelength]*/, unsigned short bytelength);  // header (gLink)
short GT_SetGLinkDoBit(short slaveno /*0..63*/, short doIndex /*0..31*/, unsigned char value /*0..1*/);  // header (gLink)
short GT_GetGLinkDiBit(short slaveno /*0..63*/, short diIndex /*0..31*/, unsigned char *pValue);  // header (gLink)

// emulator only: the field side of the modules
short GTE_SetExtDi(short mdl /*0..15*/, short index /*0..31*/, short active /*0..1*/);
short GTE_SetExtAdVoltage(short mdl /*0..15*/, short chn /*0..7*/, double voltage);
short GTE_SetGLinkDi(short slaveno /*0..63*/, short diIndex /*0..31*/, short active /*0..1*/);
"""
