"""Buffered commands of the interpolation FIFO and the G0 lines (vendor GTS / GTN headers):
outputs, DAC values and limit switches changed where the path reaches them, the FIFO's
remaining entries, the coordinate map base.

Implemented by :mod:`gtecat.gt.buffered_calls` over the coordinate systems of
:mod:`gtecat.controller.crd`.
"""

NAME = "buffered"
TITLE = "buffered interpolation commands"

PROTOTYPES = r"""
// buffered commands of the interpolation FIFO (vendor GTS / GTN headers)
short GT_BufDoBit(short crd /*1..2*/, short doType, short index, short value /*0..1*/, short fifo=0 /*0..1*/);  // header (GTN)
short GT_BufDA(short crd /*1..2*/, short chn, short daValue, short fifo=0 /*0..1*/);  // header (GTS)
short GT_BufLmtsOn(short crd /*1..2*/, short axis, short limitType, short fifo=0 /*0..1*/);  // header (GTS)
short GT_BufLmtsOff(short crd /*1..2*/, short axis, short limitType, short fifo=0 /*0..1*/);  // header (GTS)
short GT_LnXYZG0(short crd /*1..2*/, long x, long y, long z, double synVel, double synAcc, short fifo=0 /*0..1*/);  // header (GTS)
short GT_LnXYZAG0(short crd /*1..2*/, long x, long y, long z, long aPos, double synVel, double synAcc, short fifo=0 /*0..1*/);  // header (GTS; the vendor names it a)
short GT_CrdData(short crd /*1..2*/, TCrdData *pCrdData /*opt*/, short fifo=0 /*0..1*/);  // header (GTS)
short GT_GetRemainderSegNum(short crd /*1..2*/, long *pSegment, short fifo=0 /*0..1*/);  // header (GTS)
short GT_SetCrdMapBase(short crd /*1..2*/, short base);                         // header (GTS)
short GT_GetCrdMapBase(short crd /*1..2*/, short *pBase);                       // header (GTS)
"""
