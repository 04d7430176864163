"""PT motion, electronic gear, Follow (manual 7.4-7.6)."""

NAME = "pt_gear_follow"
TITLE = "PT, electronic gear and Follow"

PROTOTYPES = r"""
short GT_PrfPt(short profile, short mode=0);                                     // 89
short GT_PtData(short profile, double pos, long time, short type=0, short fifo=0);  // 93
short GT_PtSpace(short profile, short *pSpace, short fifo=0);                    // 94
short GT_PtClear(short profile, short fifo=0);                                   // 92
short GT_PtStart(long mask /*mask*/, long option=0 /*mask*/);                    // 95
short GT_SetPtLoop(short profile, long loop);                                    // 119
short GT_GetPtLoop(short profile, long *pLoop);                                  // 66
short GT_SetPtMemory(short profile, short memory);                               // 120
short GT_GetPtMemory(short profile, short *pMemory);                             // 67
short GT_GetPtRemainder(short profile, long *pRemainder);                        // 68
short GT_PrfGear(short profile, short dir=0);                                    // 87
short GT_SetGearMaster(short profile, short masterIndex, short masterType=2, short masterItem=0);  // 110
short GT_GetGearMaster(short profile, short *pMasterIndex, short *pMasterType /*opt*/, short *pMasterItem /*opt*/);  // 53
short GT_SetGearRatio(short profile, long masterEven, long slaveEven, long masterSlope=0);  // 111
short GT_GetGearRatio(short profile, long *pMasterEven, long *pSlaveEven, long *pMasterSlope /*opt*/);  // 54
short GT_GearStart(long mask /*mask*/);                                          // 24
short GT_PrfFollow(short profile, short dir=0);                                  // 86
short GT_SetFollowMaster(short profile, short masterIndex, short masterType=2, short masterItem=0);  // 108
short GT_GetFollowMaster(short profile, short *pMasterIndex, short *pMasterType /*opt*/, short *pMasterItem /*opt*/);  // 50
short GT_SetFollowLoop(short profile, long loop);                                // 107
short GT_GetFollowLoop(short profile, long *pLoop);                              // 49
short GT_SetFollowEvent(short profile, short event, short masterDir=1, long pos=0);  // 106
short GT_GetFollowEvent(short profile, short *pEvent, short *pMasterDir /*opt*/, long *pPos /*opt*/);  // 48
short GT_FollowData(short profile, long masterSegment, double slaveSegment, short type=0, short fifo=0);  // 20
short GT_FollowSpace(short profile, short *pSpace, short fifo=0);                // 21
short GT_FollowClear(short profile, short fifo=0);                               // 19
short GT_FollowStart(long mask /*mask*/, long option=0 /*mask*/);                // 22
short GT_FollowSwitch(long mask /*mask*/);                                       // 23
short GT_SetFollowMemory(short profile, short memory);                           // 109
short GT_GetFollowMemory(short profile, short *pMemory);                         // 51
"""
