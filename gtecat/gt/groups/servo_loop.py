"""The pulse and analog servo loop of GTS cards, and the card-level calls around it (vendor GTS
and GTN headers): PID sets, control and step modes, DAC and ADC channels, limit modes, DI
edge counters, timed output pulses, multi-axis enable, resource counts, the card number and
the core the GT_ functions address.

Implemented by :mod:`gtecat.gt.servo_loop_calls` (state in :mod:`gtecat.controller.servo_loop`).
"""

NAME = "servo_loop"
TITLE = "pulse and analog servo loop (GTS cards)"

PROTOTYPES = r"""
// pulse / analog servo loop of GTS cards (vendor GTS and GTN headers)
short GT_SetPid(short control, short index /*1..2*/, TPid *pPid /*in*/);        // header (GTS)
short GT_GetPid(short control, short index /*1..2*/, TPid *pPid);               // header (GTS)
short GT_CtrlMode(short axis, short mode /*0..1*/);                             // header (GTS)
short GT_StepDir(short step);                                                    // header (GTS)
short GT_StepPulse(short step);                                                  // header (GTS)
short GT_SetDac(short dac, short *pValue /*in[count]*/, short count=1);          // header (GTS)
short GT_GetDac(short dac, short *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // header (GTS)
short GT_GetAdc(short adc, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // header (GTS)
short GT_GetAdcValue(short adc, short *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // header (GTS)

// card IO around the loop (vendor GTS / GTN headers)
short GT_GetDiEx(short diType, long *pValue /*out[count]*/, short count=1);      // header (GTN)
short GT_SetDoBitReverse(short doType, short doIndex, short value /*0..1*/, short reverseTime /*1..32767*/);  // header (GTS)
short GT_GetDiReverseCount(short diType, short diIndex, unsigned long *pReverseCount /*out[count]*/, short count=1);  // header (GTS)
short GT_SetDiReverseCount(short diType, short diIndex, unsigned long *pReverseCount /*in[count]*/, short count=1);  // header (GTS)
short GT_LmtSns(unsigned short sense);                                           // header (GTS)
short GT_SetSense(short dataType, short dataIndex, short value /*0..1*/);        // header (GTN)
short GT_GetSense(short dataType, short dataIndex, short *pValue);               // header (GTN)
short GT_MultiAxisOn(unsigned long mask /*mask*/);                               // header (GTS)
short GT_MultiAxisOff(unsigned long mask /*mask*/);                              // header (GTS)
short GT_LmtsOnEx(short axis, short limitType=-1, short limitMode=-1);          // header (GTN)
short GT_LmtsOffEx(short axis, short limitType=-1, short limitMode=-1);         // header (GTN)
short GT_SetSoftLimitMode(short axis, short mode /*0..1*/);                     // header (GTN)
short GT_GetSoftLimitMode(short axis, short *pMode);                            // header (GTN)
short GT_GetResMax(short type, short *pCount);                                   // header (GTN)
short GT_GetResCount(short type, short *pCount);                                 // header (GTN)
short GT_SetCardNo(short index);                                                 // header (GTS)
short GT_GetCardNo(short *pIndex);                                               // header (GTS)
short GT_SetCore(short core /*1..2*/);                                           // header (GTN)
short GT_GetCore(short *pCore);                                                  // header (GTN)
short GT_GetAtlTorque(short axis, short *pTorque);                               // header (GTN)
short GT_GetEcatAxisAtlTorque(short axis, short *pTorque);                       // header (GTN, the manual's AtI spelled Atl)

// emulator only: the field side of the card's analog inputs
short GTE_SetAdc(short adc /*1..8*/, double voltage /*-10..10*/);
"""
