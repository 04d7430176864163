"""Card IO, encoder capture and controller-side smart home of the GTS pulse card (vendor GTS header)."""

NAME = "gts_card"
TITLE = "GTS card IO, capture and smart home"

PROTOTYPES = r"""
short GT_GetDi(short diType, long *pValue);                                      // header (GTS)
short GT_GetDiRaw(short diType, long *pValue);                                   // header (GTS)
short GT_SetDo(short doType, long value);                                        // header (GTS)
short GT_SetDoBit(short doType, short doIndex, short value /*0..1*/);            // header (GTS)
short GT_GetDo(short doType, long *pValue);                                      // header (GTS)
short GT_SetCaptureMode(short encoder, short mode /*0..3*/);                     // header (GTS)
short GT_GetCaptureMode(short encoder, short *pMode /*out[count]*/, short count=1);  // header (GTS)
short GT_GetCaptureStatus(short encoder, short *pStatus /*out[count]*/, long *pValue /*out[count]*/, short count=1, unsigned long *pClock=NULL);  // header (GTS)
short GT_SetCaptureSense(short encoder, short mode /*1..3*/, short sense /*0..1*/);  // header (GTS)
short GT_ClearCaptureStatus(short encoder);                                      // header (GTS)
short GT_GoHome(short axis, THomePrm *pHomePrm /*in*/);                          // header (GTS smart home)
short GT_GetHomePrm(short axis, THomePrm *pHomePrm);                             // header (GTS smart home)
short GT_GetHomeStatus(short axis, THomeStatus *pHomeStatus);                    // header (GTS smart home)
short GTE_SetGpi(short gpi /*1..16*/, short value /*0..1*/);
"""
