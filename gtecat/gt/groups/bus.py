"""Open/close, the clock, EtherCAT start, the raw process image, IO slaves and SDO (manual chapter 5, chapter 13)."""

NAME = "bus"
TITLE = "controller and EtherCAT bring-up"

PROTOTYPES = r"""
short GT_Open(short channel=0, short param=1);                                   // 84
short GT_Close();                                                                // 7
short GT_Reset();                                                                // 96
short GT_GetClock(unsigned long *pClock, unsigned long *pLoop=NULL);             // 33
short GT_GetVersion(char **pVersion /*outstr[64]*/);                             // 78 (the vendor header's char **; Python takes a buffer too)
short GT_InitEcatComm();                                                         // 79
short GT_StartEcatComm();                                                        // 129
short GT_TerminateEcatComm();                                                    // 136
short GT_IsEcatReady(short *pStatus);                                            // 80
short GT_GetEcatSlaves(short *pSlaveCnt, short *pIoSlaveCnt=NULL);              // 45 (+ header)
short GT_GetMcEcatAxisNum(short *pNum);                                          // 56
short GT_GetEcatPdoLength(short *pLength);                                       // header
short GT_GetEcatSlaveInfo(short slave, TSlaveInfo *pInfo);                       // header
short GT_GetEcatRawData(unsigned short offset, unsigned short size, unsigned char *pValue /*out[size]*/);  // 44
short GT_SetEcatRawData(unsigned short offset, unsigned short size, unsigned char *pValue /*in[size]*/);   // 104
short GT_EcatIOReadInput(unsigned short slave, unsigned short offset, unsigned short nSize, unsigned char *pValue /*out[nSize]*/);  // 11 (core first too)
short GT_EcatIOWriteOutput(unsigned short slave, unsigned short offset, unsigned short nSize, unsigned char *pValue /*in[nSize]*/);  // 12 (core first too)
short GT_EcatIOBitWriteOutput(unsigned short slave, unsigned short offset, unsigned short bit /*0..7*/, unsigned char value /*0..1*/);  // header
short GT_EcatIOSynch();                                                          // header
short GT_EcatSDODownload(unsigned short slave_position, unsigned short index, unsigned char subindex, unsigned char *pData /*in[data_size]*/, unsigned long data_size, unsigned long *pAbort_code=NULL);  // 13
short GT_EcatSDOUpload(unsigned short slave_position, unsigned short index, unsigned char subindex, unsigned char *pTarget /*out[target_size]*/, unsigned long target_size, unsigned long *pResult_size=NULL, unsigned long *pAbort_code=NULL);  // 14
"""
