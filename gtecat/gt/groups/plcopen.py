"""PLCopen-style single-call moves of the GTN header: ``GT_MoveVelocity`` (``TMoveVelocityPrm``)
and ``GT_MoveAbsolute`` (``TMoveAbsolutePrm``), with their readers.

Implemented by :mod:`gtecat.gt.plcopen_calls` over the Jog and Trap profiles.
"""

NAME = "plcopen"
TITLE = "single-call moves (MoveVelocity, MoveAbsolute)"

PROTOTYPES = r"""
// single-call moves (vendor GTN header)
short GT_MoveVelocity(short profile, TMoveVelocityPrm *pPrm /*in*/);            // header (GTN)
short GT_GetMoveVelocity(short profile, TMoveVelocityPrm *pPrm);                // header (GTN)
short GT_MoveAbsolute(short profile, TMoveAbsolutePrm *pPrm /*in*/);            // header (GTN)
short GT_GetMoveAbsolute(short profile, TMoveAbsolutePrm *pPrm);                // header (GTN)
"""
