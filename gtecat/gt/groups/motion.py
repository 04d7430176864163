"""Trap and Jog profiles, profile/axis/encoder readings (manual chapter 7)."""

NAME = "motion"
TITLE = "profiles, Trap, Jog and positions"

PROTOTYPES = r"""
short GT_PrfTrap(short profile);                                                 // 90
short GT_PrfJog(short profile);                                                  // 88
short GT_GetPrfMode(short profile, long *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 63
short GT_SetTrapPrm(short profile, TTrapPrm *pPrm /*in*/);                       // 125
short GT_GetTrapPrm(short profile, TTrapPrm *pPrm);                              // 74
short GT_SetPos(short profile, long pos);                                        // 115
short GT_GetPos(short profile, long *pPos);                                      // 59
short GT_SetVel(short profile, double vel);                                      // 127
short GT_GetVel(short profile, double *pVel);                                    // 77
short GT_SetJogPrm(short profile, TJogPrm *pPrm /*in*/);                         // 113
short GT_GetJogPrm(short profile, TJogPrm *pPrm);                                // 55
short GT_Update(long mask /*mask*/);                                             // 137
short GT_Stop(long mask /*mask*/, long option /*mask*/);                         // 131
short GT_GetPrfPos(short profile, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 64
short GT_GetPrfVel(short profile, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 65
short GT_GetPrfAcc(short profile, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 62
short GT_GetAxisPrfPos(short axis, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 31
short GT_GetAxisPrfVel(short axis, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 32
short GT_GetAxisPrfAcc(short axis, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 30
short GT_GetAxisEncPos(short axis, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 27
short GT_GetAxisEncVel(short axis, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 28
short GT_GetAxisEncAcc(short axis, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 26
short GT_GetAxisError(short axis, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 29
short GT_GetEncPos(short encoder, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 46
short GT_GetEncVel(short encoder, double *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // 47
short GT_SetEncPos(short encoder, long encPos);                                  // 105
short GT_SetPrfPos(short profile, long prfPos);                                  // 118
short GT_ZeroPos(short axis, short count=1);                                     // 138
short GT_SynchAxisPos(long mask /*mask*/);                                       // 135
"""
