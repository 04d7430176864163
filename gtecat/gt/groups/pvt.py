"""PVT motion (vendor GTS / GTN headers): tables of time, position and velocity points that
profiles in PVT mode follow with cubic segments, started together by mask.

Implemented by :mod:`gtecat.gt.pvt_calls` (planner :mod:`gtecat.controller.motion.pvt`).
"""

NAME = "pvt"
TITLE = "PVT motion"

PROTOTYPES = r"""
// PVT mode (vendor GTS / GTN headers)
short GT_PrfPvt(short profile);  // header
short GT_SetPvtLoop(short profile, long loop);  // header
short GT_GetPvtLoop(short profile, long *pLoopCount, long *pLoop);  // header
short GT_PvtStatus(short profile, short *pTableId, double *pTime /*out[count]*/, short count=1);  // header
short GT_PvtStart(long mask /*mask*/);  // header
short GT_PvtTableSelect(short profile, short tableId /*1..32*/);  // header
short GT_PvtTable(short tableId /*1..32*/, long count /*2..1024*/, double *pTime /*in[count]*/, double *pPos /*in[count]*/, double *pVel /*in[count]*/);  // header
short GT_PvtTableEx(short tableId /*1..32*/, long count /*2..1024*/, double *pTime /*in[count]*/, double *pPos /*in[count]*/, double *pVelBegin /*in[count]*/, double *pVelEnd /*in[count]*/);  // header
short GT_PvtTableComplete(short tableId /*1..32*/, long count /*2..1024*/, double *pTime /*in[count]*/, double *pPos /*in[count]*/, double *pA /*out[count]*/, double *pB /*out[count]*/, double *pC /*out[count]*/, double velBegin=0, double velEnd=0);  // header
short GT_PvtTableClear(short tableId /*1..32*/);  // header
"""
