/* Extension IO modules from C, as a GTS application calls them (vendor ExtMdl functions),
 * plus the GTN cores' forms and the field helpers.  Prints "key value" lines. */
#include <stdio.h>
#include "gts.h"

static void say(const char *k, long v) { printf("%s %ld\n", k, v); }

int main(void)
{
    unsigned short v = 0;
    double volts = 0;
    long di = 0;
    say("open", GT_Open(0, 1));
    say("before", GT_SetExtIoBit(0, 3, 0));
    say("openext", GT_OpenExtMdl("gts.dll"));
    say("load", GT_LoadExtConfig("D:\\cfg\\ExtModule.cfg"));
    say("reset", GT_ResetExtMdl());
    say("setbit", GT_SetExtIoBit(0, 3, 0));
    say("dorc", GT_GetExtDoValue(0, &v));
    say("do", v);
    say("field", GTE_SetExtDi(0, 5, 1));
    say("dirc", GT_GetExtIoValue(0, &v));
    say("di", v);
    say("badmdl", GT_SetExtIoBit(16, 0, 0));
    say("absent", GT_SetExtIoBit(5, 0, 0));
    say("ad", GTE_SetExtAdVoltage(1, 0, 2.5));
    say("adrc", GT_GetExtAdVoltage(1, 0, &volts));
    say("mv", (long)(volts * 1000));
    say("gts", GT_SetExtIoBitGts(0, 0, 4, 0));
    say("gtscard", GT_SetExtIoBitGts(1, 0, 4, 0));
    say("gtninit", GTN_ExtModuleInit(1, 1));
    say("gtndirc", GTN_GetExtDi(1, 1, &di));
    say("gtndi", di);
    say("close", GT_CloseExtMdl());
    say("done", 1);
    return 0;
}
