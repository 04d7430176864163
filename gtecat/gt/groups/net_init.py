"""Bring-up of GSN-E and ring-net controllers (vendor GTN header, ``gxn.dll``): open the
card, initialise its EtherCAT network, read a ring-net axis's absolute encoder.

Implemented by :mod:`gtecat.gt.net_init_calls`.
"""

NAME = "net_init"
TITLE = "GSN-E and ring-net bring-up"

PROTOTYPES = r"""
// no core: they open and bring up the whole controller (vendor GTN header)
short GTN_OpenCard(short channel=0, char *pPrm=NULL /*str*/, char *pFileName=NULL /*str*/);  // header (GTN: void *pPrm, reserved)
short GTN_NetInit(short mode=0, char *pPrm=NULL /*str*/, short overTime=0, long *pStatus=NULL);  // header (GTN)
short GTN_RN_GetAbsEncPosEx(short core, short encoder, long long *pEncPos);  // header (GTN)
"""
