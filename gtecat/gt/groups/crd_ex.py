"""Buffered interpolation with double coordinates (the vendor GTN header's ``Ex`` forms, used
with its look-ahead), and ``GT_BufGear``: an axis outside the coordinate system carried
along with the next segment.

Implemented by :mod:`gtecat.gt.crd_ex_calls` over :mod:`gtecat.controller.crd`.
"""

NAME = "crd_ex"
TITLE = "interpolation Ex forms and BufGear"

PROTOTYPES = r"""
// lines and arcs with double coordinates (vendor GTN header)
short GT_LnXYEx(short crd /*1..2*/, double x, double y, double synVel, double synAcc, long segNum, short override2 /*0..1*/, short fifo=0 /*0..1*/);  // header (GTN)
short GT_LnXYG0Ex(short crd /*1..2*/, double x, double y, double synVel, double synAcc, long segNum, short override2 /*0..1*/, short fifo=0 /*0..1*/);  // header (GTN)
short GT_LnXYZEx(short crd /*1..2*/, double x, double y, double z, double synVel, double synAcc, long segNum, short override2 /*0..1*/, short fifo=0 /*0..1*/);  // header (GTN)
short GT_LnXYZG0Ex(short crd /*1..2*/, double x, double y, double z, double synVel, double synAcc, long segNum, short override2 /*0..1*/, short fifo=0 /*0..1*/);  // header (GTN)
short GT_LnXYZAEx(short crd /*1..2*/, double x, double y, double z, double aPos, double synVel, double synAcc, long segNum, short override2 /*0..1*/, short fifo=0 /*0..1*/);  // header (GTN; the vendor names it a)
short GT_LnXYZAG0Ex(short crd /*1..2*/, double x, double y, double z, double aPos, double synVel, double synAcc, long segNum, short override2 /*0..1*/, short fifo=0 /*0..1*/);  // header (GTN; the vendor names it a)
short GT_ArcXYREx(short crd /*1..2*/, double x, double y, double radius, short circleDir /*0..1*/, double synVel, double synAcc, long segNum, short override2 /*0..1*/, short fifo=0 /*0..1*/);  // header (GTN)
short GT_ArcXYCEx(short crd /*1..2*/, double x, double y, double xCenter, double yCenter, short circleDir /*0..1*/, double synVel, double synAcc, long segNum, short override2 /*0..1*/, short fifo=0 /*0..1*/);  // header (GTN)
short GT_ArcYZREx(short crd /*1..2*/, double y, double z, double radius, short circleDir /*0..1*/, double synVel, double synAcc, long segNum, short override2 /*0..1*/, short fifo=0 /*0..1*/);  // header (GTN)
short GT_ArcYZCEx(short crd /*1..2*/, double y, double z, double yCenter, double zCenter, short circleDir /*0..1*/, double synVel, double synAcc, long segNum, short override2 /*0..1*/, short fifo=0 /*0..1*/);  // header (GTN)
short GT_ArcZXREx(short crd /*1..2*/, double z, double x, double radius, short circleDir /*0..1*/, double synVel, double synAcc, long segNum, short override2 /*0..1*/, short fifo=0 /*0..1*/);  // header (GTN)
short GT_ArcZXCEx(short crd /*1..2*/, double z, double x, double zCenter, double xCenter, short circleDir /*0..1*/, double synVel, double synAcc, long segNum, short override2 /*0..1*/, short fifo=0 /*0..1*/);  // header (GTN)
short GT_CrdDataEx(short crd /*1..2*/, TCrdData *pCrdData /*opt*/, short fifo=0 /*0..1*/);  // header (GTN)

// an axis carried along with the next segment (vendor GTS / GTN headers)
short GT_BufGear(short crd /*1..2*/, short gearAxis, long pos, short fifo=0 /*0..1*/);  // header (GTS)
short GT_BufGearEx(short crd /*1..2*/, short gearAxis, double deltaPos, short fifo=0 /*0..1*/);  // header (GTN)
"""
