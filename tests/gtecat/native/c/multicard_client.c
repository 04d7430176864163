/* A client of the older multi-card GTS ABI: short cardNum first in every GT_ function.
 * Built with `gcc prog.c $(gtecat lib --abi gts-multicard --cflags --libs)`. */
#include <stdio.h>
#include "gts.h"

static void say(const char *key, int value) { printf("%s %d\n", key, value); }

static void why(const char *key)
{
    char text[512];
    GTE_GetLastError(text, sizeof text);
    printf("%s %s\n", key, text);
}

int main(void)
{
    say("open_card1", GT_Open(1, 0, 1));
    why("open_card1_reason");
    say("open", GT_Open(0, 0, 1));
    say("reset", GT_Reset(0));
    say("init", GT_InitEcatComm(0));
    short ready = 0;
    for (int i = 0; i < 200 && !ready; i++)
        GT_IsEcatReady(0, &ready);
    say("ready", ready);
    say("start", GT_StartEcatComm(0));
    long sts = 0;
    say("getsts", GT_GetSts(0, 1, &sts, 1, NULL));
    say("axison_card2", GT_AxisOn(2, 1));
    why("axison_card2_reason");
    say("prftrap", GT_PrfTrap(0, 1));
    long mode = -1;
    say("prfmode_rc", GT_GetPrfMode(0, 1, &mode, 1, NULL));
    say("prfmode", (int)mode);
    say("hsio", GT_SetHSIOOpt(0, 1, 0));
    say("close", GT_Close(0));
    say("done", 1);
    return 0;
}
