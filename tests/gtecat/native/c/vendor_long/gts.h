/* A header in the style of the vendor's GTS gts.h (written for these tests): C long in the
   structures and prototypes, __stdcall, no includes. 4-byte long on Windows; on 64-bit Linux
   only a 32-bit build (gtecat lib --m32) gives these structures their Windows layout. */
#pragma once
#define GT_API extern "C" short __stdcall

typedef struct HomePrm
{
	short mode;
	short moveDir;
	short indexDir;
	short edge;
	short triggerIndex;
	short pad1[3];
	double velHigh;
	double velLow;
	double acc;
	double dec;
	short smoothTime;
	short pad2[3];
	long homeOffset;
	long searchHomeDistance;
	long searchIndexDistance;
	long escapeStep;
	long pad3[2];
} THomePrm;

typedef struct HomeStatus
{
	short run;
	short stage;
	short error;
	short pad1;
	long capturePos;
	long targetPos;
} THomeStatus;

GT_API GT_Open(short channel=0,short param=1);
GT_API GT_Close(void);
GT_API GT_ClrSts(short axis,short count=1);
GT_API GT_AxisOn(short axis);
GT_API GT_GetSts(short axis,long *pSts,short count=1,unsigned long *pClock=NULL);
GT_API GT_GetPrfPos(short profile,double *pValue,short count=1,unsigned long *pClock=NULL);
GT_API GT_GoHome(short axis,THomePrm *pHomePrm);
GT_API GT_GetHomePrm(short axis,THomePrm *pHomePrm);
GT_API GT_GetHomeStatus(short axis,THomeStatus *pHomeStatus);
