/* A client of the older multi-card GTS ABI: short cardNum first in every GT_ function.
 * Built with `gcc prog.c $(gtecat lib --abi gts-multicard --cflags --libs)`.
 * Two cards, each a controller of its own: card 1 jogs its axis 1 while card 0 does not,
 * card 0 closes and card 1 keeps running. */
#include <stdio.h>
#include "gts.h"

static void say(const char *key, int value) { printf("%s %d\n", key, value); }

static void why(const char *key)
{
    char text[512];
    GTE_GetLastError(text, sizeof text);
    printf("%s %s\n", key, text);
}

static int bring_up(short card)
{
    int rc = GT_Open(card, 0, 1);
    rc |= GT_Reset(card);
    rc |= GT_InitEcatComm(card);
    short ready = 0;
    for (int i = 0; i < 2000 && !ready; i++)
        GT_IsEcatReady(card, &ready);
    rc |= GT_StartEcatComm(card);
    return rc ? rc : !ready;
}

int main(void)
{
    say("open_card16", GT_Open(16, 0, 1));
    why("open_card16_reason");
    say("up0", bring_up(0));
    say("axison_card2", GT_AxisOn(2, 1)); /* a card this program has not opened */
    why("axison_card2_reason");
    say("up1", bring_up(1));
    say("open1_again", GT_Open(1, 0, 1));
    say("axison0", GT_AxisOn(0, 1));
    say("axison1", GT_AxisOn(1, 1));
    say("prfjog1", GT_PrfJog(1, 1));
    TJogPrm jog = {0.5, 0.5, 0.0};
    say("setjog1", GT_SetJogPrm(1, 1, &jog));
    say("setvel1", GT_SetVel(1, 1, 20.0));
    say("update1", GT_Update(1, 1));
    unsigned long clk = 0, start = 0;
    GT_GetClock(0, &start, NULL);
    for (int i = 0; i < 100000 && clk < start + 100; i++)
        GT_GetClock(0, &clk, NULL); /* polling card 0 for 100 ms: card 1 moves meanwhile */
    double v0 = -1, v1 = -1, p1 = 0;
    say("prfvel0_rc", GT_GetPrfVel(0, 1, &v0, 1, NULL));
    say("prfvel1_rc", GT_GetPrfVel(1, 1, &v1, 1, NULL));
    GT_GetPrfPos(1, 1, &p1, 1, NULL);
    say("vel0", (int)v0);
    say("vel1", (int)v1);
    say("moved1", p1 > 100.0);
    long mode0 = -1, mode1 = -1;
    GT_GetPrfMode(0, 1, &mode0, 1, NULL);
    GT_GetPrfMode(1, 1, &mode1, 1, NULL);
    say("mode0", (int)mode0); /* Trap 0 */
    say("mode1", (int)mode1); /* Jog 1 */
    say("hsio", GT_SetHSIOOpt(0, 1, 0));
    say("close0", GT_Close(0));
    long sts = 0;
    say("getsts0_closed", GT_GetSts(0, 1, &sts, 1, NULL));
    say("getsts1", GT_GetSts(1, 1, &sts, 1, NULL));
    say("running1", (int)((sts >> 10) & 1));
    say("stop1", GT_Stop(1, 1, 0));
    say("close1", GT_Close(1));
    say("done", 1);
    return 0;
}
