"""EtherCAT IO seen through the controller's own terminals (vendor GTN header): a general-purpose
output of the controller wired to a bit of a slave, and one bit of a drive's digital outputs.

Implemented by :mod:`gtecat.gt.ecat_io_calls`.
"""

NAME = "ecat_io"
TITLE = "EtherCAT IO mapped to the controller's terminals"

PROTOTYPES = r"""
// EtherCAT bits behind the controller's terminals (vendor GTN header)
short GT_RelateEcatSlaveToMcGpoBit(short gpo /*1..32*/, short ecatIndex, short ecatType /*0..1*/, short bitOffset, short pdoOffset);  // header (GTN)
short GT_GetEcatAxisDOBit(short axis, short bitIndex /*0..31*/, char *pValue /*out[1]*/);  // header (GTN)
"""
