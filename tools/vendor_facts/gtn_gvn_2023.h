/* Facts read from a public GTN/GVN-era vendor gts.h (about 605,000 characters, with a
 * __linux__ section and the GP_CORE/HS_CORE cores) that this repository does not hold:
 * the prototypes, structures and constants of its first sections (basic functions,
 * status, limits, configuration, capture and triggers) that the function table lacked,
 * written out again for tools/gts_header_table.py.  Not the vendor's file: no comments,
 * our layout; only what a call needs (types, names, defaults, field order). */

#define GP_CORE 1
#define HS_CORE 2
#define DSP_SPORT_2_0 2
#define DSP_POWER_OFF_RECOVER 5

#define MC_ACTVEL 33
#define MC_PRF_VEL 34
#define MC_PRF_POS 35
#define MC_CRD 36
#define MC_DR_FOLLOW_ERROR 37
#define MC_COMBINE_AXES 38
#define MC_SERVO_READY 39
#define MC_SERVO_READY_TO_SWITCH_ON 49
#define MC_NET_PORT 51
#define MC_SERIAL_NUMBER 55
#define MC_REMOTE_AU_ENCODER 55
#define MC_SLOTS_NUMBER 56
#define MC_SUB_TERMINAL 57
#define MC_EHMI_DI 65
#define MC_EHMI_DO 66
#define MC_LOCAL_TERMINAL_NO_RESOURCE 67
#define MC_AXIS_CONNECT 68
#define MC_LASER_AO 72
#define MC_LIMIT_POSITIVE_RAW 250
#define MC_LIMIT_NEGATIVE_RAW 251
#define MC_ALARM_RAW 252
#define MC_HOME_RAW 253
#define MC_GPI_RAW 254
#define MC_ARRIVE_RAW 255
#define MC_MPG_RAW 259
#define MC_GROUP 500
#define MC_GROUP_PROFILE 501
#define MC_GROUP_SYNTHESIS 505
#define MC_GROUP_RTCP 510

#define PROFILE_MODE_NONE -1
#define PROFILE_MODE_TRAP 0
#define PROFILE_MODE_JOG 1
#define PROFILE_MODE_PT 2
#define PROFILE_MODE_GEAR 3
#define PROFILE_MODE_FOLLOW 4
#define PROFILE_MODE_CRD 5
#define PROFILE_MODE_PVT 6
#define PROFILE_MODE_CAM 7
#define PROFILE_MODE_FOLLOW_EX 10
#define PROFILE_MODE_MOVE_ABSOLUTE 20
#define PROFILE_MODE_MOVE_VELOCITY 30
#define PROFILE_MODE_MOVE_CONTINUOUS 40
#define PROFILE_MODE_MOVE_JOG 41
#define PROFILE_MODE_MOVE_SYNCHRONIZATION 42
#define PROFILE_MODE_MOVE_POS 48
#define PROFILE_MODE_GROUP_MOVE_NONE 100
#define PROFILE_MODE_GROUP_MOVE_CONTINUOUS 140
#define PROFILE_MODE_GROUP_MOVE_JOG 141
#define PROFILE_MODE_GROUP_MOVE_SYNCHRONIZATION 142
#define PROFILE_MODE_GROUP_MOVE_POS 148
#define PROFILE_MODE_GROUP_MOVE_PATH 150

#define LIMIT_MODE_EXTERMAL 0
#define LIMIT_MODE_SOFT 1
#define LIMIT_MODE_ALL -1
#define LIMIT_TYPE_POS 0
#define LIMIT_TYPE_NEG 1
#define LIMIT_TYPE_ALL -1

#define RESET_TYPE_NONE -1
#define RESET_TYPE_IO 0
#define STEP_DIR 0
#define STEP_PULSE 1
#define STEP_ORTHOGONAL 2
#define CAPTURE_POSCOMPARE 6
#define TRIGGER_RESULT_FIFO_MODE_STATIC 0
#define TRIGGER_RESULT_FIFO_MODE_LOOP 1
#define LATCH_USER_VAR_DOUBLE 100
#define LATCH_USER_VAR_LONG 101

#define NET_INIT_MODE_AUTO 0
#define NET_INIT_MODE_SKIP_TERMINAL 1
#define NET_INIT_MODE_MULT_OPEN 2
#define NET_INIT_MODE_MOTION_STUDIO 99
#define NET_INIT_MODE_XML_STRICT 100
#define NO_NET 15
#define RING_NET 6
#define ETHERCAT_NET 8
#define ETHERCAT_RING_MISC_NET 9
#define NET_SRC_NONE 15
#define NET_SRC_FROM_RING_NET 6
#define NET_SRC_FROM_ECAT_NET 8

typedef struct { short mode; } TResetIo;
typedef union { TResetIo resetIo; double data[7]; } TResetModePrmUnion;
typedef struct { short axisIndex[2]; short reserve1[2]; double radius; double center[2]; } TAxisCircularSafetyZone;
typedef struct { short refType; short refIndex; short reserve1[2]; double refRatio; double limitPositive; double limitNegative; } TProfileReferenceSafetyZone;
typedef struct {
  short hwLmtPositiveEnable; short hwLmtNegativeEnable; short swLmtPositiveEnable; short swLmtNegativeEnable;
  short hwLmtPositiveStatus; short hwLmtNegativeStatus; short swLmtPositiveStatus; short swLmtNegativeStatus;
} TLimitInfo;
typedef struct { short mode; short reserve1[3]; double adjustMinError; double reserve2[8]; } TPulseCloseWorkModePrm;
typedef struct { unsigned long latchIndex; long latchValue; double userValue; double reserve; } TTriggerLatchPrm;

GT_API GTN_OpenRingNet(short channel = 5, short param = 2, char *pFile = NULL, short index = 1, long count = 1);
GT_API GTN_RingNetInit(short mode, char *pFile, short index);
GT_API GTN_SetResetMode(short core, short type, TResetModePrmUnion *pResetPrm);
GT_API GTN_SetDeviceShareMax(short core, short count);
GT_API GTN_GetDeviceShareMax(short core, short *pCount);
GT_API GTN_GetChipTemperature(double *pTempValue, double *pMinValue, double *pMaxValue);
GT_API GTN_SetTemperatureEnable(short core, short enable);
GT_API GTN_GetTemperature(short core, double *pTemperature);
GT_API GTN_GetStsEx(short core, short axis, long *pSts, short count = 1, unsigned long *pClock = NULL);
GT_API GTN_GetDriverSts(short core, short axis, long *pSts, short count = 1, unsigned long *pClock = NULL);
GT_API GTN_GetDriverPosErr(short core, short station, short axis, long *posError);
GT_API GTN_SetDryRunVel(short core, short crd, double vel, double velG0);
GT_API GTN_GetDryRunVel(short core, short crd, double *pVel, double *pVelG0);
GT_API GTN_SetDryRunMode(short core, short crd, short mode);
GT_API GTN_GetDryRunMode(short core, short crd, short *pMode);
GT_API GTN_SetDrvPrfVel(short core, short axis, long *pPrfVel, short count);
GT_API GTN_GetDrvAtlVel(short core, short axis, long *pPrfVel, short count);
GT_API GTN_StopPro(short core, short *pAxis, short *pOption, short count);
GT_API GTN_SetPrfPosEx(short core, short profile, double pos);
GT_API GTN_SynchAxisPosPro(short core, short *pAxis, short count);
GT_API GTN_GetLimitInfo(short core, short axis, TLimitInfo *pInfo);
GT_API GTN_SetSoftLimitTrimMode(short core, short enable);
GT_API GTN_SetLimit(short core, short axis, short type, void *pPrm);
GT_API GTN_GetLimit(short core, short axis, short type, void *pPrm);
GT_API GTN_SetPulseCloseWorkMode(short core, short axis, TPulseCloseWorkModePrm *pPulseModePrm);
GT_API GTN_SetFeedOverrideMode(short core, short mode);
GT_API GTN_GetFeedOverrideMode(short core, short *pMode);
GT_API GTN_ClearAlarm(short core, short axis, short count, unsigned short delayTime);
GT_API GTN_LmtsOnEx(short core, short axis, short limitType = -1, short limitMode = -1);
GT_API GTN_LmtsOffEx(short core, short axis, short limitType = -1, short limitMode = -1);
GT_API GTN_SetAxisPosErrLimit(short core, short axis, long errorLimit);
GT_API GTN_GetAxisPosErrLimit(short core, short axis, long *pErrorLimit);
GT_API GTN_SetProbeCaptureStopAxis(short core, short encoder, short stopAxis, short stopType, short enable);
GT_API GTN_SetAxisFilterArrivalBand(short core, short axis, double band, long time);
GT_API GTN_GetAxisFilterArrivalBand(short core, short axis, double *pBand, long *pTime);
GT_API GTN_SetAuEncoderScale(short core, short i, long alpha, long beta);
GT_API GTN_GetAuEncoderScale(short core, short i, long *pAlpha, long *pBeta);
GT_API GTN_SetEncoderMapRelation(short core, short masterEncType, short masterEncIndex, short mapEncType, short mapEncIndex);
GT_API GTN_GetEncoderMapRelation(short core, short masterEncType, short masterEncIndex, short *pMapEncType, short *pMapEncIndex);
GT_API GTN_SetProfilePpr(short core, short profile, double ppr);
GT_API GTN_GetProfilePpr(short core, short profile, double *pPpr);
GT_API GTN_SetAuTrigger(short core, short index, TTriggerEx *pTrigger);
GT_API GTN_GetAuTrigger(short core, short index, TTriggerEx *pTrigger);
GT_API GTN_DisableAuTrigger(short core, short index);
GT_API GTN_ClearAuTriggerStatus(short core, short index);
GT_API GTN_GetAuTriggerStatus(short core, short index, TTriggerStatusEx *pTriggerStatusEx, short count = 1);
GT_API GTN_SetTriggerPrm(short core, short index, TTriggerPrm *pTriggerPrm);
GT_API GT_SetCaptureRepeatFifoMode(short encoder, short mode);
GT_API GT_GetCaptureRepeatFifoMode(short encoder, short *pMode);
