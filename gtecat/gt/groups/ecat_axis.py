"""Axis enable, CiA-402 modes, drive-side homing and touch probe (manual 5.2.2.1-5.2.2.3)."""

NAME = "ecat_axis"
TITLE = "EtherCAT axes, drive homing and touch probe"

PROTOTYPES = r"""
short GT_AxisOn(short axis);                                                     // 5
short GT_AxisOff(short axis);                                                    // 4
short GT_SetEcatAxisMode(short axis, short mode);                                // 100
short GT_GetEcatAxisMode(short axis, unsigned short *pMode);                     // 39 (the vendor header's unsigned short *; the manual writes short *)
short GT_GetEcatEncPos(short axis, long *pEncPos);                               // 41
short GT_GetEcatEncVel(short axis, long *pEncVel);                               // 42
short GT_GetEcatAxisPE(short axis, long *pPosErr);                               // 40
short GT_GetEcatAxisDI(short axis, unsigned long *pDi);                          // 37
short GT_GetEcatAxisDO(short axis, unsigned long *pDo);                          // 38
short GT_GetEcatAxisAtITorque(short axis, short *pTorque);                       // 36
short GT_GetEcatAxisAtICurrent(short axis, short *pCur);                         // 35
short GT_GetEcatErrorCode(short axis, unsigned short *pErrorCode);               // header
short GT_SetEcatAxisDO(short axis, unsigned long DoValue);                       // 99
short GT_GetEcatAxisAI(short axis, short channel, short *pValue);                // 34
short GT_SetEcatAxisPT(short axis, short torque);                                // 101
short GT_SetEcatAxisPV(short axis, long velocity);                               // 102
short GT_SetPosScale(short axis, unsigned short scale);                          // 117
short GT_GetPosScale(short axis, unsigned short *pScale);                        // 61
short GT_GetEcatAxisPdoData(short axis, unsigned short object, unsigned char *pData /*out[?]*/);  // header (the object's size)
short GT_SetHomingMode(short axis, short mode);                                  // 112
short GT_SetEcatHomingPrm(short axis, short method, double speed1, double speed2, double acc, long offset, unsigned short probeFunction);  // 103
short GT_StartEcatHoming(short axis);                                            // 130
short GT_StopEcatHoming(short axis);                                             // 133
short GT_GetEcatHomingStatus(short axis, unsigned short *pHomingStatus);         // 43 (the vendor header's unsigned short *; the manual writes short *)
short GT_SetTouchProbeFunction(short axis, short ProbePrm);                      // 123
short GT_SetTouchProbeFunctionEx(short axis, short Probe1Enable, short Probe1TriggerType, short Probe1TriggerLevel, short Probe2Enable, short Probe2TriggerType, short Probe2TriggerLevel);  // 124
short GT_GetTouchProbeStatus(short axis, unsigned short *probeStatus /*opt*/, long *probe1RiseValue /*opt*/, long *probe1FallValue /*opt*/, long *probe2RiseValue /*opt*/, long *probe2FallValue /*opt*/);  // 73
"""
