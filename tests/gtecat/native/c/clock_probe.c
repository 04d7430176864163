/* How controller time moves for a native client: across a usleep, and across GTE_Wait.
 * Prints `key value` lines.  gcc clock_probe.c $(python3 -m gtecat lib --cflags --libs) */
#define _DEFAULT_SOURCE
#include <stdio.h>
#include <unistd.h>

#include "gts.h"

int main(void)
{
    unsigned long a = 0, b = 0, c = 0;
    short rc = GT_Open(0, 1);
    printf("open %d\n", rc);
    if (rc != 0)
        return 1;
    GT_GetClock(&a, NULL);
    usleep(300000);
    GT_GetClock(&b, NULL);
    rc = GTE_Wait(100);
    GT_GetClock(&c, NULL);
    printf("wait_rc %d\n", rc);
    printf("sleep_ms %lu\n", b - a);
    printf("wait_ms %lu\n", c - b);
    unsigned long t0 = 0, t1 = 0;
    GT_GetClock(&t0, NULL);
    for (int i = 0; i < 2000; i++) { /* a tight polling loop: no sleep */
        long sts;
        GT_GetSts(1, &sts, 1, NULL);
    }
    GT_GetClock(&t1, NULL);
    printf("poll2000_ms %lu\n", t1 - t0);
    GT_Close();
    return 0;
}
