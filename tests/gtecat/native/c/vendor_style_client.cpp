// A C++ client written against a vendor-style header (vendor_style/gts.h), compiled with
// gtecat's flags and nothing else: `g++ -Ivendor_style prog.cpp $(gtecat lib --cflags --libs)`.
#include "gts.h"
#include <cstdio>

static void say(const char *key, int value) { std::printf("%s %d\n", key, value); }

static void why(const char *key)
{
    char text[512];
    GTE_GetLastError(text, sizeof text);
    std::printf("%s %s\n", key, text);
}

int main()
{
    say("open", GT_Open());
    GT_InitEcatComm();
    short ready = 0;
    for (int i = 0; i < 200 && !ready; i++)
        GT_IsEcatReady(&ready);
    say("start", GT_StartEcatComm());
    char *version = NULL;
    say("version_rc", GT_GetVersion(&version));
    std::printf("version %s\n", version ? version : "(null)");
    unsigned long clock = 0;
    say("clock_rc", GT_GetClock(&clock));  // pLoop defaults to NULL
    TTrapPrm trap;
    say("prftrap", GT_PrfTrap(1));
    say("gettrap", GT_GetTrapPrm(1, &trap));
    trap.acc = 0.25;
    trap.dec = 0.5;
    trap.smoothTime = 5;
    say("settrap", GT_SetTrapPrm(1, &trap));
    TTrapPrm back;
    GT_GetTrapPrm(1, &back);
    say("trap_smooth", back.smoothTime);
    say("trap_acc_x100", (int)(back.acc * 100 + 0.5));
    say("hsio", GT_SetHSIOOpt(1));  // declared by the vendor header, not emulated
    why("hsio_reason");
    short count = -1;
    int rc = GTN_GetResCount(1, MC_AXIS, &count);
    say("rescount", rc);
    say("rescount_value", count);
    TMoveVelocityPrm mv = {10, 1, 1, 0, 0, 1};
    say("movevelocity", GTN_MoveVelocity(1, 1, &mv));
    why("movevelocity_reason");
    say("close", GT_Close());
    say("done", 1);
    return 0;
}
