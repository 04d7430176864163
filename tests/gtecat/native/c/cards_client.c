/* Two cards through the one-card ABI: GT_SetCardNo chooses the card every later call
 * addresses (before GT_Open too, as applications call it).
 * Built with `gcc prog.c $(gtecat lib --cflags --libs)`. */
#include <stdio.h>
#include "gts.h"

static void say(const char *key, int value) { printf("%s %d\n", key, value); }

static int bring_up(void)
{
    int rc = GT_Open(0, 1);
    rc |= GT_InitEcatComm();
    short ready = 0;
    for (int i = 0; i < 2000 && !ready; i++)
        GT_IsEcatReady(&ready);
    rc |= GT_StartEcatComm();
    rc |= GT_AxisOn(1);
    return rc ? rc : !ready;
}

int main(void)
{
    short card = -1;
    say("set16", GT_SetCardNo(16));
    say("set1", GT_SetCardNo(1)); /* before GT_Open */
    say("get_rc", GT_GetCardNo(&card));
    say("card", card);
    say("up1", bring_up());
    say("set0", GT_SetCardNo(0));
    say("up0", bring_up());
    GT_SetCardNo(1);
    TJogPrm jog = {0.5, 0.5, 0.0};
    int rc = GT_PrfJog(1) | GT_SetJogPrm(1, &jog) | GT_SetVel(1, -10.0) | GT_Update(1);
    say("jog1", rc);
    GT_SetCardNo(0);
    unsigned long clk = 0, start = 0;
    GT_GetClock(&start, NULL);
    for (int i = 0; i < 100000 && clk < start + 100; i++)
        GT_GetClock(&clk, NULL); /* card 0 is polled, card 1 moves */
    double v0 = -1, v1 = 1;
    GT_GetPrfVel(1, &v0, 1, NULL);
    GT_SetCardNo(1);
    GT_GetPrfVel(1, &v1, 1, NULL);
    say("vel0", (int)v0);
    say("vel1", (int)v1);
    say("close1", GT_Close());
    long sts = 0;
    say("sts1_closed", GT_GetSts(1, &sts, 1, NULL));
    GT_SetCardNo(0);
    say("sts0", GT_GetSts(1, &sts, 1, NULL));
    say("servo0", (int)((sts >> 9) & 1));
    short core = 0, axes = 0;
    say("setcore2", GT_SetCore(2)); /* GT_x address core 2, the card's second core */
    say("getcore_rc", GT_GetCore(&core));
    say("core", core);
    say("rescount_rc", GT_GetResCount(MC_AXIS, &axes));
    say("core2_axes", axes);
    say("setcore3", GT_SetCore(3));
    say("setcore1", GT_SetCore(1));
    say("close0", GT_Close());
    say("done", 1);
    return 0;
}
