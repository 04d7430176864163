"""Position compare and triggers (vendor GTS and GTN headers): the 2D compare of GTS cards
(points in two FIFOs, a pulse or level output at each), the GTN position compare (FIFO and
linear modes, one or two dimensions) and the position triggers (a position latched at an
input's edge).

Implemented by :mod:`gtecat.gt.compare_calls` (units in :mod:`gtecat.controller.compare`
and :mod:`gtecat.controller.trigger`).
"""

NAME = "compare"
TITLE = "position compare and triggers"

PROTOTYPES = r"""
// 2D position compare of GTS cards (vendor GTS header); chn 0 = HSIO0, 1 = HSIO1
short GT_2DCompareMode(short chn /*0..1*/, short mode /*0..1*/);  // header (GTS)
short GT_2DComparePulse(short chn /*0..1*/, short level /*0..1*/, short outputType /*0..1*/, short time);  // header (GTS)
short GT_2DCompareStop(short chn /*0..1*/);  // header (GTS)
short GT_2DCompareClear(short chn /*0..1*/);  // header (GTS)
short GT_2DCompareClearData(short chn /*0..1*/);  // header (GTS)
short GT_2DCompareStatus(short chn /*0..1*/, short *pStatus, long *pCount, short *pFifo, short *pFifoCount, short *pBufCount=NULL);  // header (GTS)
short GT_2DCompareSetPrm(short chn /*0..1*/, T2DComparePrm *pPrm /*in*/);  // header (GTS)
short GT_2DCompareData(short chn /*0..1*/, short count, T2DCompareData *pBuf /*in[count]*/, short fifo /*0..1*/);  // header (GTS)
short GT_2DCompareStart(short chn /*0..1*/);  // header (GTS)
short GT_SetComparePort(short channel /*0..1*/, short hsio0 /*0..15*/, short hsio1 /*0..15*/);  // header (GTS)

// position compare of the GTN header: the GT_ and GTN_ forms both take the core first
short GT_SetPosCompareMode(short core, short index /*1..8*/, TPosCompareMode *pMode /*in*/);  // header (GTN)
short GTN_SetPosCompareMode(short core, short index /*1..8*/, TPosCompareMode *pMode /*in*/);  // header (GTN)
short GT_GetPosCompareMode(short core, short index /*1..8*/, TPosCompareMode *pMode);  // header (GTN)
short GTN_GetPosCompareMode(short core, short index /*1..8*/, TPosCompareMode *pMode);  // header (GTN)
short GT_PosCompareData(short core, short index /*1..8*/, TPosCompareData *pData /*in*/);  // header (GTN)
short GTN_PosCompareData(short core, short index /*1..8*/, TPosCompareData *pData /*in*/);  // header (GTN)
short GT_PosCompareData2D(short core, short index /*1..8*/, TPosCompareData2D *pData /*in*/);  // header (GTN)
short GTN_PosCompareData2D(short core, short index /*1..8*/, TPosCompareData2D *pData /*in*/);  // header (GTN)
short GT_SetPosCompareLinear(short core, short index /*1..8*/, TPosCompareLinear *pLinear /*in*/);  // header (GTN)
short GTN_SetPosCompareLinear(short core, short index /*1..8*/, TPosCompareLinear *pLinear /*in*/);  // header (GTN)
short GT_GetPosCompareLinear(short core, short index /*1..8*/, TPosCompareLinear *pLinear);  // header (GTN)
short GTN_GetPosCompareLinear(short core, short index /*1..8*/, TPosCompareLinear *pLinear);  // header (GTN)
short GT_SetPosCompareLinear2D(short core, short index /*1..8*/, TPosCompareLinear2D *pLinear /*in*/);  // header (GTN)
short GTN_SetPosCompareLinear2D(short core, short index /*1..8*/, TPosCompareLinear2D *pLinear /*in*/);  // header (GTN)
short GT_GetPosCompareLinear2D(short core, short index /*1..8*/, TPosCompareLinear2D *pLinear);  // header (GTN)
short GTN_GetPosCompareLinear2D(short core, short index /*1..8*/, TPosCompareLinear2D *pLinear);  // header (GTN)
short GT_PosCompareStart(short core, short index /*1..8*/);  // header (GTN)
short GTN_PosCompareStart(short core, short index /*1..8*/);  // header (GTN)
short GT_PosCompareStop(short core, short index /*1..8*/);  // header (GTN)
short GTN_PosCompareStop(short core, short index /*1..8*/);  // header (GTN)
short GT_PosCompareClear(short core, short index /*1..8*/);  // header (GTN)
short GTN_PosCompareClear(short core, short index /*1..8*/);  // header (GTN)
short GT_PosCompareStatus(short core, short index /*1..8*/, TPosCompareStatus *pStatus);  // header (GTN)
short GTN_PosCompareStatus(short core, short index /*1..8*/, TPosCompareStatus *pStatus);  // header (GTN)
short GT_PosCompareInfo(short core, short index /*1..8*/, TPosCompareInfo *pInfo);  // header (GTN)
short GTN_PosCompareInfo(short core, short index /*1..8*/, TPosCompareInfo *pInfo);  // header (GTN)
short GTN_PosCompareSpace(short core, short index /*1..8*/, unsigned short *pSpace);  // header (GTN)

// position triggers (vendor GTS / GTN headers); TTriggerEx names the latched resource
short GT_SetTrigger(short i, TTrigger *pTrigger /*in*/);  // header
short GT_GetTrigger(short i, TTrigger *pTrigger);  // header
short GT_SetTriggerEx(short i, TTriggerEx *pTrigger /*in*/);  // header (GTN)
short GT_GetTriggerEx(short i, TTriggerEx *pTrigger);  // header (GTN)
short GT_GetTriggerStatus(short i, TTriggerStatus *pTriggerStatus /*out[count]*/, short count=1);  // header
short GT_GetTriggerStatusEx(short i, TTriggerStatusEx *pTriggerStatusEx /*out[count]*/, short count=1);  // header
short GT_ClearTriggerStatus(short i);  // header
"""
