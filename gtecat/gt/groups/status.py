"""Status words, limits, stop decelerations, scales, LoadConfig (manual chapters 6, 9, 11)."""

NAME = "status"
TITLE = "status, safety and axis configuration"

PROTOTYPES = r"""
short GT_GetSts(short axis, long *pSts /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 71
short GT_ClrSts(short axis, short count=1);                                      // 8
short GT_GetPrfSts(short profile, long *pSts /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // header (GTN era)
short GT_AlarmOn(short axis);                                                    // 3
short GT_AlarmOff(short axis);                                                   // 2
short GT_LmtsOn(short axis, short limitType=-1);                                 // 82
short GT_LmtsOff(short axis, short limitType=-1);                                // 81
short GT_SetSoftLimit(short axis, long positive, long negative);                 // 121 (9.2.2)
short GT_GetSoftLimit(short axis, long *pPositive, long *pNegative);             // 69
short GT_SetPosErr(short control, long error);                                   // 116
short GT_GetPosErr(short control, long *pError);                                 // 60
short GT_SetStopDec(short profile, double decSmoothStop, double decAbruptStop);  // 122
short GT_GetStopDec(short profile, double *pDecSmoothStop, double *pDecAbruptStop);  // 70
short GT_SetAxisBand(short axis, long band, long time);                          // 98
short GT_GetAxisBand(short axis, long *pBand, long *pTime);                      // 25
short GT_ProfileScale(short axis, short alpha, short beta);                      // 91
short GT_EncScale(short axis, short alpha, short beta);                          // 17
short GT_EncSns(unsigned short sense);                                           // 18
short GT_EncOn(short encoder);                                                   // 16
short GT_EncOff(short encoder);                                                  // 15
short GT_LoadConfig(char *pFile /*str*/);                                        // 83
"""
