"""gtecat's own GTE_ functions: virtual time, cable pulls, machine positions."""

NAME = "emulator"
TITLE = "emulator functions"

PROTOTYPES = r"""
short GTE_Wait(double ms /*0..86400000*/);
short GTE_UnplugSlave(short slave);
short GTE_ReplugSlave(short slave);
short GTE_GetMachinePos(short axis, double *pValue);
short GTE_SetProgramSpeed(double instructionsPerMs /*1..10000000*/);
short GTE_GetThreadError(short thread /*0..31*/, char *pText /*outstr[256]*/);
"""
