/* A header written here in the style of the vendor's Windows gts.h (not the vendor's
 * file): the stdcall macro, C++ linkage in GT_API, NULL as a default argument without
 * <stddef.h>, Windows type names.  gtecat's `lib --cflags` must make it compile on Linux
 * unchanged. */
#pragma once

#define GT_API extern "C" short __stdcall

#define CMD_SUCCESS                     (0)
#define CMD_ERROR_UNKNOWN               (8)
#define MC_AXIS                         (30)

typedef struct TrapPrm
{
    double acc;
    double dec;
    double velStart;
    short  smoothTime;
} TTrapPrm;

typedef struct
{
    double vel;
    double acc;
    double dec;
    double jerkBegin;
    double jerkEnd;
    short direction;
} TMoveVelocityPrm;

GT_API GT_Open(short channel=0,short param=1);
GT_API GT_Close(void);
GT_API GT_InitEcatComm(void);
GT_API GT_IsEcatReady(short *pStatus);
GT_API GT_StartEcatComm(void);
GT_API GT_GetVersion(char **pVersion);
GT_API GT_GetClock(unsigned long *pClock,unsigned long *pLoop=NULL);
GT_API GT_PrfTrap(short profile);
GT_API GT_SetTrapPrm(short profile,TTrapPrm *pPrm);
GT_API GT_GetTrapPrm(short profile,TTrapPrm *pPrm);
GT_API GT_SetHSIOOpt(unsigned short value,unsigned short laserChannel=0);
GT_API GT_SetGLinkDoBit(short slaveno,short doIndex,UINT8 value);
GT_API GTN_GetResCount(short core,short type,short *pCount);
GT_API GTN_MoveVelocity(short core,short profile,TMoveVelocityPrm *pPrm);
GT_API GTE_GetLastError(char *buf, short size);
