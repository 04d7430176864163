// The vendor GTN header's shapes, as its Qt/MFC demos call them (EtherCAT demo):
// GTN_Open(5) / GTN_Open() with the default channel, GTN_Close(void), and
// GTN_GetEcatAxisPdoData(core, axis, object, (unsigned char *)&value) with three
// parameters after the core. Prints "key value" lines.
#include <cstdio>
#include <unistd.h>
#include "gts.h"

static void say(const char *k, long v) { std::printf("%s %ld\n", k, v); }

int main()
{
    say("open5", GTN_Open(5));
    say("init", GTN_InitEcatComm(1));
    short ready = 0;
    for (int i = 0; i < 100 && !ready; i++) {
        GTN_IsEcatReady(1, &ready);
        if (!ready)
            usleep(20000);
    }
    say("ready", ready);
    say("start", GTN_StartEcatComm(1));
    unsigned short sw = 0;
    say("pdo_rc", GTN_GetEcatAxisPdoData(1, 1, 0x6041, (unsigned char *)&sw));
    say("sw_nonzero", sw != 0);
    say("close", GTN_Close());
    say("open_default", GTN_Open());
    say("close2", GTN_Close());
    say("done", 1);
    return 0;
}
