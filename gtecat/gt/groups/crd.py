"""Coordinate systems, segment FIFOs, arcs and lines, look-ahead (vendor header, manual table 10-2)."""

NAME = "crd"
TITLE = "coordinated motion"

PROTOTYPES = r"""
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
"""
