"""Lead-screw compensation (vendor GTS / GTN headers): a table of errors along an axis, one
list per direction of travel, added to the command on its way to the drive.

Implemented by :mod:`gtecat.gt.lead_screw_calls` (:mod:`gtecat.controller.lead_screw`).
"""

NAME = "lead_screw"
TITLE = "lead-screw compensation"

PROTOTYPES = r"""
short GT_SetLeadScrewComp(short axis, short n /*2..1024*/, long startPos, long lenPos, long *pPositive /*in[n]*/, long *pNegative /*in[n]*/);  // header
short GT_EnableLeadScrewComp(short axis, short mode /*0..1*/);  // header
"""
