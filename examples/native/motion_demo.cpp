// A C++ motion program in the shape of a typical Qt application's `Motion` helper class
// for a Googol card: static wrappers around the GT_* calls, an axis enum, status decoding,
// homing, point-to-point moves - compiled unchanged against gtecat's gts.h / libgts.so:
//
//     g++ motion_demo.cpp $(python3 -m gtecat lib --cflags --libs) -o motion_demo
//     GTECAT_ENI=manual_fig5_2.eni ./motion_demo
//
// Nothing needs to be started first: GT_Open starts a private controller that ends with
// the program.  With GTECAT_CONTROLLER=unix:/path it attaches to a running one instead
// (a test can then drive the machine's field side meanwhile).
//
// Arguments: [home_method] [watch_ms].  home_method is the CiA 402 method (default 37:
// the current position is home); watch_ms > 0 adds a long move that the program watches
// for a drive alarm (status bit 1) for at most that many ms of controller time.
#include "gts.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <vector>

enum Axis
{
    Axis_X = 1,
    Axis_Y = 2,
};

static const long kStsAlarm = 1L << 1;     // the drive is in alarm (table 6-2)
static const long kStsEnabled = 1L << 9;   // servo enabled
static const long kStsMoving = 1L << 10;   // profile moving

class Motion
{
public:
    static short init();
    static short close();
    static short axisStatus(Axis axis, long *sts);
    static short isMoving(Axis axis, bool *moving);
    static short stop(const std::vector<Axis> &axes);
    static short moveTo(Axis axis, long pos, double vel);
    static short waitDone(Axis axis, long timeout_ms, bool *alarm);
    static short home(Axis axis, short method);
    static unsigned long clockMs();

private:
    static short report(const char *what, short ret);
};

short Motion::report(const char *what, short ret)
{
    if (ret != 0)
    {
        char reason[256];
        GTE_GetLastError(reason, sizeof reason);
        std::printf("error %s returned %d: %s\n", what, ret, reason);
    }
    return ret;
}

unsigned long Motion::clockMs()
{
    unsigned long ms = 0;
    GT_GetClock(&ms);
    return ms;
}

short Motion::init()
{
    short ret = GT_Open();  // the vendor's default arguments (channel 0, param 1)
    if (report("GT_Open", ret))
        return ret;
    ret = GT_InitEcatComm();
    if (report("GT_InitEcatComm", ret))
        return ret;
    short ready = 0;
    for (int i = 0; i < 100 && !ready; i++)  // the vendor demo polls with a sleep
    {
        ret = GT_IsEcatReady(&ready);
        if (!ready)
            usleep(50 * 1000);
    }
    if (!ready)
    {
        std::printf("error the EtherCAT bus did not come up\n");
        return -1;
    }
    if (report("GT_StartEcatComm", ret = GT_StartEcatComm()))
        return ret;
    short axes = 0;
    GT_GetMcEcatAxisNum(&axes);
    if (report("GT_ClrSts", ret = GT_ClrSts(1, axes)))
        return ret;
    if (report("GT_ZeroPos", ret = GT_ZeroPos(1, axes)))
        return ret;
    for (short a = 1; a <= axes; a++)
    {
        if (report("GT_AxisOn", ret = GT_AxisOn(a)))
            return ret;
    }
    long sts = 0;
    for (int i = 0; i < 100; i++)  // wait for the drives to follow
    {
        axisStatus(Axis_X, &sts);
        if (sts & kStsEnabled)
            break;
        usleep(5 * 1000);
    }
    std::printf("axes %d enabled %d\n", axes, (sts & kStsEnabled) ? 1 : 0);
    return 0;
}

short Motion::close()
{
    return GT_Close();
}

short Motion::axisStatus(Axis axis, long *sts)
{
    return GT_GetSts(short(axis), sts);  // count=1, pClock=NULL: the C++ defaults
}

short Motion::isMoving(Axis axis, bool *moving)
{
    long sts = 0;
    short ret = GT_GetSts(short(axis), &sts);
    if (ret != 0)
        return ret;
    *moving = (sts & kStsMoving) != 0;
    return 0;
}

short Motion::stop(const std::vector<Axis> &axes)
{
    long mask = 0, option = 0;
    for (auto axis : axes)
    {
        mask |= 1L << (short(axis) - 1);
        option |= 1L << (short(axis) - 1);
    }
    return GT_Stop(mask, option);
}

short Motion::moveTo(Axis axis, long pos, double vel)
{
    bool moving = false;
    short ret = isMoving(axis, &moving);
    if (ret != 0)
        return ret;
    if (moving && (ret = stop({axis})) != 0)
        return ret;
    if (report("GT_PrfTrap", ret = GT_PrfTrap(short(axis))))
        return ret;
    TTrapPrm trap;
    if (report("GT_GetTrapPrm", ret = GT_GetTrapPrm(short(axis), &trap)))
        return ret;
    trap.acc = 0.5;
    trap.dec = 0.5;
    trap.smoothTime = 0;
    if (report("GT_SetTrapPrm", ret = GT_SetTrapPrm(short(axis), &trap)))
        return ret;
    if (report("GT_SetVel", ret = GT_SetVel(short(axis), vel)))
        return ret;
    if (report("GT_SetPos", ret = GT_SetPos(short(axis), pos)))
        return ret;
    return report("GT_Update", GT_Update(1L << (short(axis) - 1)));
}

short Motion::waitDone(Axis axis, long timeout_ms, bool *alarm)
{
    unsigned long start = clockMs();
    *alarm = false;
    for (;;)
    {
        long sts = 0;
        short ret = axisStatus(axis, &sts);
        if (ret != 0)
            return ret;
        if (sts & kStsAlarm)
        {
            *alarm = true;
            return 0;
        }
        if (!(sts & kStsMoving))
            return 0;
        if (long(clockMs() - start) > timeout_ms)
            return 1;
        usleep(2 * 1000);
    }
}

short Motion::home(Axis axis, short method)
{
    short ret;
    if (report("GT_ClrSts", ret = GT_ClrSts(short(axis))))
        return ret;
    if (report("GT_SetHomingMode", ret = GT_SetHomingMode(short(axis), 6)))
        return ret;
    ret = GT_SetEcatHomingPrm(short(axis), method, 2000, 500, 10000, 0, 0);
    if (report("GT_SetEcatHomingPrm", ret))
        return ret;
    if (report("GT_StartEcatHoming", ret = GT_StartEcatHoming(short(axis))))
        return ret;
    unsigned short status = 0; // the vendor header: unsigned short *
    do
    {
        usleep(5 * 1000);
        if (report("GT_GetEcatHomingStatus", ret = GT_GetEcatHomingStatus(short(axis), &status)))
            return ret;
    } while (status != HOMING_DONE && status != HOMING_FAILED);
    GT_SetHomingMode(short(axis), 8);  // back to cyclic synchronous position
    std::printf("home status %d\n", status);
    if (status != HOMING_DONE)
        return 1;
    return report("GT_ZeroPos", GT_ZeroPos(short(axis)));  // as such programs do after homing
}

int main(int argc, char **argv)
{
    short method = short(argc > 1 ? std::atoi(argv[1]) : 37);
    long watch_ms = argc > 2 ? std::atol(argv[2]) : 0;
    if (Motion::init() != 0)
        return 1;
    if (Motion::home(Axis_X, method) != 0)
        return 1;
    bool alarm = false;
    if (Motion::moveTo(Axis_X, 30000, 30.0) != 0 || Motion::waitDone(Axis_X, 10000, &alarm) != 0)
        return 1;
    double prf = 0, enc = 0;
    GT_GetPrfPos(Axis_X, &prf);
    GT_GetEncPos(Axis_X, &enc);
    std::printf("moved prf %.0f enc %.0f\n", prf, enc);
    if (watch_ms > 0)
    {
        if (Motion::moveTo(Axis_X, 2000000, 5.0) != 0)
            return 1;
        std::printf("watching\n");
        std::fflush(stdout);
        short ret = Motion::waitDone(Axis_X, watch_ms, &alarm);
        long sts = 0;
        Motion::axisStatus(Axis_X, &sts);
        GT_GetEncPos(Axis_X, &enc);
        std::printf("watch ret %d alarm %d sts 0x%lx enc %.0f\n", ret, alarm ? 1 : 0, sts, enc);
        if (alarm)
        {
            Motion::stop({Axis_X});
            GT_ClrSts(Axis_X);
        }
    }
    Motion::close();
    std::printf("done\n");
    return 0;
}
