/* The vendor demo's GTN sequence against gtecat's libgts, on examples/manual_fig5_2.eni:
 * bring-up polled with usleep, raw data, AxisOn, a Trap move, SDO with an abort code,
 * NULL optional pointers, a bad core, declared-only functions.  Prints `key value` lines the test reads.
 *
 *     gcc gtn_sequence.c $(python3 -m gtecat lib --cflags --libs)
 */
#define _DEFAULT_SOURCE /* usleep under -std=c99 too */
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "gts.h"

#define CORE 1

static char reason[512];

static void say(const char *key, long value)
{
    printf("%s %ld\n", key, value);
}

static const char *why(void)
{
    GTE_GetLastError(reason, sizeof reason);
    return reason;
}

/* where this function's frame lies: the same before and after a call whose callee pops
 * exactly the arguments it was given (32-bit Windows' __stdcall) */
static intptr_t stack_mark(void)
{
    char here = 0;
    return (intptr_t)&here;
}

int main(void)
{
    short rc, status = 0;
    int polls;

    rc = GTN_Open(5, 1); /* the vendor GTN header: channel 5, no core */
    say("open", rc);
    if (rc != 0) {
        printf("reason %s\n", why());
        return 1;
    }
    say("open_twice", GTN_Open(5, 1)); /* -6, as from Python (the first open stays) */
    printf("open_twice_reason %s\n", why());
    rc = GTN_InitEcatComm(CORE);
    say("init", rc);
    for (polls = 0; polls < 100; polls++) { /* the demo: poll, sleep, give up after 100 */
        rc = GTN_IsEcatReady(CORE, &status);
        if (rc == 0 && status == 1)
            break;
        usleep(20000);
    }
    say("ready", status);
    say("ready_polls", polls);
    say("start", GTN_StartEcatComm(CORE));

    unsigned long t0 = 0, t1 = 0;
    GTN_GetClock(CORE, &t0, NULL);
    usleep(200000);
    GTN_GetClock(CORE, &t1, NULL);
    say("slept_ms", (long)(t1 - t0));

    /* raw data: slave 2's output bytes are at 32 (manual figure 5-2) */
    unsigned char out[2] = {0xA5, 0x3C}, back[2] = {0, 0};
    say("raw_write", GTN_SetEcatRawData(CORE, 32, 2, out));
    say("raw_read", GTN_GetEcatRawData(CORE, 32, 2, back));
    say("raw_back", back[0] | (back[1] << 8));
    say("raw_write_inputs", GTN_SetEcatRawData(CORE, 34, 2, out)); /* 7: input bytes */
    short length = 0;
    say("pdo_length_rc", GTN_GetEcatPdoLength(CORE, &length));
    say("pdo_length", length);

    /* servo on */
    say("clrsts", GTN_ClrSts(CORE, 1, 1));
    say("axis_on", GTN_AxisOn(CORE, 1));
    long sts = 0;
    for (polls = 0; polls < 200; polls++) {
        GTN_GetSts(CORE, 1, &sts, 1, NULL);
        if (sts & (1L << 9))
            break;
        usleep(5000);
    }
    say("enabled", (sts >> 9) & 1);

    /* Trap move to 20000 */
    TTrapPrm trap;
    say("prftrap", GTN_PrfTrap(CORE, 1));
    say("gettrap", GTN_GetTrapPrm(CORE, 1, &trap));
    trap.acc = 1.0;
    trap.dec = 1.0;
    trap.velStart = 0;
    trap.smoothTime = 0;
    say("settrap", GTN_SetTrapPrm(CORE, 1, &trap));
    say("setvel", GTN_SetVel(CORE, 1, 50.0));
    say("setpos", GTN_SetPos(CORE, 1, 20000));
    say("update", GTN_Update(CORE, 1 << 0));
    for (polls = 0; polls < 1000; polls++) {
        usleep(10000);
        GTN_GetSts(CORE, 1, &sts, 1, NULL);
        if (!(sts & (1L << 10)))
            break;
    }
    say("move_polls", polls);
    double prf = 0, enc = 0;
    unsigned long clk = 0;
    say("getprfpos", GTN_GetPrfPos(CORE, 1, &prf, 1, &clk));
    say("getencpos", GTN_GetEncPos(CORE, 1, &enc, 1, NULL));
    say("prfpos", (long)prf);
    say("encpos", (long)enc);
    long ecat = 0;
    say("ecatencpos_rc", GTN_GetEcatEncPos(CORE, 1, &ecat));
    say("ecatencpos", ecat);

    /* SDO: statusword of slave 0, then an object that does not exist */
    unsigned char data[8];
    unsigned long size = 0, abort_code = 0;
    memset(data, 0, sizeof data);
    say("sdo_up", GTN_EcatSDOUpload(CORE, 0, 0x6041, 0, data, sizeof data, &size, &abort_code));
    say("sdo_size", (long)size);
    say("sdo_abort", (long)abort_code);
    rc = GTN_EcatSDOUpload(CORE, 0, 0x1234, 0, data, sizeof data, &size, &abort_code);
    say("sdo_bad", rc);
    say("sdo_bad_abort", (long)abort_code);
    printf("sdo_bad_reason %s\n", why());
    say("sdo_nulls", GTN_EcatSDOUpload(CORE, 0, 0x6041, 0, data, sizeof data, NULL, NULL));
    unsigned char word[2] = {8, 0}; /* 6060h: cyclic synchronous position */
    abort_code = 1;
    say("sdo_down", GTN_EcatSDODownload(CORE, 0, 0x6060, 0, word, 1, &abort_code));
    say("sdo_down_abort", (long)abort_code);

    /* NULL pointers: optional ones are fine, a required one is 7 */
    say("null_optional", GTN_GetSts(CORE, 1, &sts, 1, NULL));
    say("null_required", GTN_GetSts(CORE, 1, NULL, 1, NULL));
    printf("null_required_reason %s\n", why());
    short n_motion = 0;
    say("slaves_one_ptr", GTN_GetEcatSlaves(CORE, &n_motion, NULL));
    say("slaves", n_motion);

    /* out of range, unknown core */
    say("bad_axis", GTN_GetSts(CORE, 99, &sts, 1, NULL));
    say("bad_core", GTN_GetSts(7, 1, &sts, 1, NULL));
    printf("bad_core_reason %s\n", why());
    say("bad_count", GTN_GetSts(CORE, 1, &sts, 0, NULL));

    /* declared-only functions: a GTN twin (its core, longs and doubles), one taking a
     * structure by value; each says which it is */
    intptr_t mark = stack_mark();
    say("declared_arc", GTN_ArcXYCOverride2(CORE, 1, 100, 200, 1.5, 2.5, 0, 10.0, 0.5, 0.0, 0));
    printf("declared_arc_reason %s\n", why());
    TScanPosSuperposeParamter superpose;
    memset(&superpose, 0, sizeof superpose);
    say("declared_struct", GTN_SetScanPosSuperposeParameter(CORE, 1, superpose));
    printf("declared_struct_reason %s\n", why());
    say("declared_stack", stack_mark() == mark);

    /* several values at once; GT_ spelling (core 1 implied) */
    long two[2] = {0, 0};
    say("sts_two", GT_GetSts(1, two, 2, NULL));
    char *version = NULL; /* the vendor header's char **: the library keeps the text */
    say("version_rc", GT_GetVersion(&version));
    printf("version %s\n", version);

    say("last_error_null", GTE_GetLastError(NULL, 10));
    say("close", GTN_Close());
    say("after_close", GTN_GetSts(CORE, 1, &sts, 1, NULL));
    printf("after_close_reason %s\n", why());
    say("reopen", GTN_Open(5, 1));
    say("reopen_sts", GTN_GetSts(CORE, 1, &sts, 1, NULL));
    say("done", 1);
    return 0;
}
