"""Gantry pairs (vendor GTS header): a slave axis driven with its master's command.

Implemented by :mod:`gtecat.gt.gantry_calls` over the electronic gear.
"""

NAME = "gantry"
TITLE = "gantry (master and slave axes)"

PROTOTYPES = r"""
// gantry (vendor GTS header)
short GT_SetGantryMode(short group /*1..8*/, short master, short slave, short mode, long syncErrorLimit=1000);  // header (GTS)
short GT_GetGantryMode(short group /*1..8*/, short *pMaster, short *pSlave, short *pMode, long *pSyncErrorLimit);  // header (GTS)
"""
