"""The motion-program compiler and threads, MRAM (manual chapters 10, 11.8, 12)."""

NAME = "programs"
TITLE = "motion programs, MRAM and MAC address"

PROTOTYPES = r"""
short GT_Compile(char *pFileName /*str*/, TCompileInfo *pWrongInfo);              // 9
short GT_Download(char *pFileName /*str*/);                                      // 10
short GT_GetFunId(char *pFunName /*str*/, short *pFunId);                        // 52
short GT_GetVarId(char *pFunName /*str opt*/, char *pVarName /*str*/, TVarInfo *pVarInfo);  // 75
short GT_Bind(short thread /*0..31*/, short funId, short page /*0..31*/);       // 6
short GT_RunThread(short thread /*0..31*/);                                      // 97
short GT_StopThread(short thread /*0..31*/);                                     // 134
short GT_PauseThread(short thread /*0..31*/);                                    // 85
short GT_GetThreadSts(short thread /*0..31*/, TThreadSts *pThreadSts);           // 72
short GT_SetVarValue(short page /*-1..31*/, TVarInfo *pVarInfo /*in*/, double *pValue /*in[count]*/, short count=1 /*1..6*/);  // 126
short GT_GetVarValue(short page /*-1..31*/, TVarInfo *pVarInfo /*in*/, double *pValue /*out[count]*/, short count=1 /*1..6*/);  // 76
short GT_SetMRAMData(short address /*0..4095*/, short *pData /*in[count]*/, short count /*1..24*/);  // 114
short GT_GetMRAMData(short address /*0..4095*/, short *pData /*out[count]*/, short count /*1..24*/);  // 57
short GT_StartAccessMRAM(short address /*0..4095*/, short count /*1..4096*/, short mode /*0..1*/);  // 128
short GT_StopAccessMRAM();                                                       // 132
short GT_GetMRAMStatus(short *pSts);                                             // 58
short GetMacAddress(unsigned long ulAdapterNumber, unsigned char *pMacAddress /*out[ulAddressSize]*/, unsigned long ulAddressSize);  // 1 (chapter 12)
short GT_GetMacAddress(unsigned long ulAdapterNumber, unsigned char *pMacAddress /*out[ulAddressSize]*/, unsigned long ulAddressSize);  // 1 (chapter 12, the GT_ spelling)
"""
