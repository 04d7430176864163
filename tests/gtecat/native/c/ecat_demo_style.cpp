// The GT calls of Googol's EtherCAT Qt demo, in its style, written here (no Qt): they
// must compile against gtecat's gts.h as they do against the vendor's.
#include "gts.h"

static short core = 1;

short bring_up()
{
    short rtn = GTN_Open(5, 1);
    rtn = GTN_Reset(core);
    rtn = GTN_InitEcatComm(core);
    short ready = 0;
    do {
        rtn = GTN_IsEcatReady(core, &ready);
    } while (ready != 1 && rtn == CMD_SUCCESS);
    rtn = GTN_StartEcatComm(core);
    short axes = 0;
    rtn = GTN_GetResCount(core, MC_AXIS, &axes);
    return rtn == CMD_SUCCESS ? axes : -1;
}

short jog(short axis, short dir)
{
    TMoveVelocityPrm prm;
    prm.vel = 10;
    prm.acc = 1;
    prm.dec = 1;
    prm.jerkBegin = 0;
    prm.jerkEnd = 0;
    prm.direction = dir;
    return GTN_MoveVelocity(core, axis, &prm);
}

short homing(short axis)
{
    unsigned short mode = 0, status = 0;
    GTN_SetHomingMode(core, axis, 6);
    GTN_GetEcatAxisMode(core, axis, &mode);
    GTN_SetEcatHomingPrm(core, axis, 17, 20, 2, 1, 0, 0);
    GTN_StartEcatHoming(core, axis);
    GTN_GetEcatHomingStatus(core, axis, &status);
    unsigned short sw = 0;
    GTN_GetEcatAxisPdoData(core, axis, 0x6041, (unsigned char *)&sw);
    long enc = 0;
    GTN_GetEcatEncPos(core, axis, &enc);
    double prf = 0;
    GTN_GetPrfPos(core, axis, &prf);
    long sts = 0;
    GTN_GetSts(core, axis, &sts);
    return GTN_StopEcatHoming(core, axis) == CMD_SUCCESS && mode == 6 && status != 0;
}

int main()
{
    bring_up();
    jog(1, 1);
    homing(1);
    GTN_TerminateEcatComm(core);
    return GTN_Close();
}
