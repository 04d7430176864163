// A C++ client of the newest GTN/GVN-era header shape (vendor_gvn/gts.h), compiled with
// gtecat's flags: `g++ -Ivendor_gvn prog.cpp $(gtecat lib --cflags --libs)`.  It reads the
// profiles' status words as a field application does (GTN_GetPrfSts(1, 1, sts, 5)) and
// calls two functions gtecat declares but does not emulate.
#include "gts.h"
#include <cstdio>

static void say(const char *key, long value) { std::printf("%s %ld\n", key, value); }

static void why(const char *key)
{
    char text[512];
    GTE_GetLastError(text, sizeof text);
    std::printf("%s %s\n", key, text);
}

int main()
{
    say("open", GTN_Open());
    GTN_InitEcatComm(GP_CORE);
    short ready = 0;
    for (int i = 0; i < 200 && !ready; i++)
        GTN_IsEcatReady(GP_CORE, &ready);
    say("start", GTN_StartEcatComm(GP_CORE));
    long sts[5] = {-1, -1, -1, -1, -1};
    say("prfsts", GTN_GetPrfSts(GP_CORE, 1, sts, 5));
    long any = 0;
    for (int i = 0; i < 5; i++)
        any |= sts[i];
    say("prfsts_any", any);
    long one = -1;
    unsigned long clock = 0;
    say("gt_prfsts", GT_GetPrfSts(1, &one, 1, &clock));
    say("gt_prfsts_value", one);
    long mode[5];
    say("prfmode", GTN_GetPrfMode(GP_CORE, 1, mode, 5));
    say("mode1", mode[0] == PROFILE_MODE_TRAP);
    say("multilines", GTN_RN_SetEncMultiLinesEx(GP_CORE, 4, 0));
    why("multilines_reason");
    TLimitInfo info;
    say("limitinfo", GTN_GetLimitInfo(GP_CORE, 1, &info));
    say("close", GTN_Close());
    say("done", 1);
    return 0;
}
