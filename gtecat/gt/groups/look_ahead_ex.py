"""The GTN header's look-ahead set-up in user units (``GT_SetupLookAheadCrd``,
``GT_InitLookAheadEx``) and the ``...ModeLa`` settings of its planner.

Implemented by :mod:`gtecat.gt.look_ahead_ex_calls` over the look-ahead of
:mod:`gtecat.controller.crd`.
"""

NAME = "look_ahead_ex"
TITLE = "look-ahead in user units"

PROTOTYPES = r"""
short GT_SetupLookAheadCrd(short crd /*1..2*/, EMachineMode machineMode);  // header (GTN)
short GT_InitLookAheadEx(short crd /*1..2*/, TLookAheadParameter *pLookAheadPara /*in*/, short fifo /*0..1*/, short motionMode=0, TPreStartPos *pPreStartPos=NULL /*in*/);  // header (GTN)
short GT_SetAxisLimitModeLa(short crd /*1..2*/, int *pAxisLimitMode /*in[8]*/);  // header (GTN)
short GT_SetWorkLimitModeLa(short crd /*1..2*/, EWorkLimitMode workLimitMode);  // header (GTN)
short GT_SetAccDefineModeLa(short crd /*1..2*/, EAccSettingDef accDefMode);  // header (GTN)
short GT_SetAxisVelValidCompModeLa(short crd /*1..2*/, int enable /*0..1*/, int *pCompAxis /*in[8]*/);  // header (GTN)
short GT_SetAxisVelValidModeLa(short crd /*1..2*/, int velValidAxis /*mask*/);  // header (GTN)
short GT_SetVelDefineModeLa(short crd /*1..2*/, EVelSettingDef velDefMode);  // header (GTN)
short GT_SetVelModeLa(short crd /*1..2*/, EVelMode velMode);  // header (GTN)
short GT_SetVelSmoothModeLa(short crd /*1..2*/, short smoothMode);  // header (GTN)
short GT_SetAxisFollowModeLa(short crd /*1..2*/, int *pFollowMode /*in[8]*/);  // header (GTN)
short GT_SetFollowAxisProcessModeLa(short crd /*1..2*/, int AxisFollowMode);  // header (GTN)
"""
