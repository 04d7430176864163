// A header in the shape of the newest GTN/GVN-era vendor gts.h (written for this test, not
// the vendor's file): a __linux__ branch of its own (GT_API without __stdcall, stdint.h,
// __int64 from int64_t), the GP_CORE/HS_CORE cores, C++ default arguments.
#pragma once

#ifdef __linux__
#define GT_API extern "C" short
#include <stdint.h>
typedef int64_t __int64;
#else
#define GT_API extern "C" short __stdcall
#include "windows.h"
#endif

#define GP_CORE (1)
#define HS_CORE (2)
#define CMD_ERROR_UNKNOWN (8)
#define PROFILE_MODE_TRAP (0)

typedef struct LimitInfo
{
    short hwLmtPositiveEnable;
    short hwLmtNegativeEnable;
    short swLmtPositiveEnable;
    short swLmtNegativeEnable;
    short hwLmtPositiveStatus;
    short hwLmtNegativeStatus;
    short swLmtPositiveStatus;
    short swLmtNegativeStatus;
} TLimitInfo;

GT_API GTN_Open(short channel = 5, short param = 2);
GT_API GTN_Close(void);
GT_API GTN_InitEcatComm(short core);
GT_API GTN_IsEcatReady(short core, short *pStatus);
GT_API GTN_StartEcatComm(short core);
GT_API GTN_AxisOn(short core, short axis);
GT_API GTN_GetPrfMode(short core, short profile, long *pValue, short count = 1, unsigned long *pClock = NULL);
GT_API GT_GetPrfSts(short profile, long *pSts, short count = 1, unsigned long *pClock = NULL);
GT_API GTN_GetPrfSts(short core, short profile, long *pSts, short count = 1, unsigned long *pClock = NULL);
GT_API GTN_GetStsEx(short core, short axis, long *pSts, short count = 1, unsigned long *pClock = NULL);
GT_API GTN_GetLimitInfo(short core, short axis, TLimitInfo *pInfo);
GT_API GTN_RN_SetEncMultiLinesEx(short core, short encoder, uint64_t multiLines);
GT_API GTE_GetLastError(char *text, short size);
